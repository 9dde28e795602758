/* MPFEM bad input: every case a documented status and a message naming the
 * problem, nothing crashes.
 *  - connectivity out of range (copied: at add_elements; borrowed: at setup),
 *    a particle repeated within an element: MFREE_ERR_INPUT;
 *  - inverted or degenerate elements (zero or negative Jacobian): LINE2 with x_2 < x_1,
 *    clockwise or collinear TRI3, non-convex QUAD4, and a QUAD4 whose physical bilinear
 *    interpolant is singular (the diamond of docs/papers.md, paper 004, choices 2):
 *    MFREE_ERR_INPUT, from
 *    mfree_mesh_setup and from the approximant's setup;
 *  - a mesh of mixed dimension (TRI3 on a 1D set, LINE2 on a 2D set): MFREE_ERR_MISMATCH;
 *  - a kernel support too small to reach any element (a point outside the mesh, a
 *    particle in no element): MFREE_FAIL_NEIGHBORS with a zero row;
 *  - MPFEM misuse: setup without a mesh (MFREE_ERR_STATE), a mesh on a non-MPFEM
 *    approximant (MFREE_ERR_UNSUPPORTED) or of another particle set
 *    (MFREE_ERR_MISMATCH), order 2, the nodal scheme at host points, Hessians of eq 21
 *    with the Haar kernel, HEX8 that are not bricks (MFREE_ERR_UNSUPPORTED), bad options
 *    (MFREE_ERR_ARG). */
#include <math.h>
#include <string.h>

#include "mpfem_util.h"

static mfree_context_t *ctx;

static int setup(void **state) {
  (void)state;
  assert_ok(NULL, mfree_context_create(&ctx));
  return 0;
}
static int teardown(void **state) {
  (void)state;
  mfree_context_destroy(&ctx);
  return 0;
}

static void test_connectivity(void **state) {
  (void)state;
  const double x[8] = {0, 0, 1, 0, 1, 1, 0, 1};
  mfree_particles_t *ps = mp_particles(ctx, 2, 4, x, 0.3);
  mfree_mesh_t *m = NULL;
  assert_ok(ctx, mfree_mesh_create(ctx, ps, &m));
  const int32_t oob[4] = {0, 1, 2, 4}, rep[3] = {0, 1, 1}, neg[3] = {0, -1, 2};
  assert_error(ctx, mfree_mesh_add_elements(m, MFREE_ELEMENT_QUAD4, 1, oob, 0, MFREE_COPY), MFREE_ERR_INPUT,
               "outside");
  assert_error(ctx, mfree_mesh_add_elements(m, MFREE_ELEMENT_TRI3, 1, rep, 0, MFREE_COPY), MFREE_ERR_INPUT, "twice");
  assert_error(ctx, mfree_mesh_add_elements(m, MFREE_ELEMENT_TRI3, 1, neg, 0, MFREE_COPY), MFREE_ERR_INPUT,
               "outside");
  const int32_t one_based[4] = {1, 2, 3, 5}; /* 5 is out of range with base 1 */
  assert_error(ctx, mfree_mesh_add_elements(m, MFREE_ELEMENT_QUAD4, 1, one_based, 1, MFREE_COPY), MFREE_ERR_INPUT,
               "outside");
  assert_error(ctx, mfree_mesh_add_elements(m, MFREE_ELEMENT_LINE2, 1, oob, 0, MFREE_COPY), MFREE_ERR_MISMATCH,
               "mixed dimension");
  assert_error(ctx, mfree_mesh_add_elements(m, (mfree_element_t)9, 1, oob, 0, MFREE_COPY), MFREE_ERR_ARG,
               "element type");
  int32_t ne = -1;
  assert_ok(ctx, mfree_mesh_get_size(m, &ne));
  assert_int_equal(ne, 0); /* nothing was added */
  /* borrowed: checked at setup, here and in the approximant */
  int32_t conn[4] = {0, 1, 2, 3};
  assert_ok(ctx, mfree_mesh_add_elements(m, MFREE_ELEMENT_QUAD4, 1, conn, 0, MFREE_BORROW));
  assert_ok(ctx, mfree_mesh_setup(m));
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MPFEM, &a));
  assert_ok(ctx, mfree_approximant_set_mesh(a, m));
  assert_ok(ctx, mfree_approximant_setup(a));
  conn[3] = 7;
  assert_error(ctx, mfree_mesh_setup(m), MFREE_ERR_INPUT, "outside");
  assert_error(ctx, mfree_approximant_setup(a), MFREE_ERR_INPUT, "outside");
  conn[3] = 3;
  assert_ok(ctx, mfree_approximant_setup(a));
  mfree_approximant_destroy(&a);
  mfree_mesh_destroy(&m);
  mfree_particles_destroy(&ps);
  /* LINE2 on a 2D set is a mesh of mixed dimension too */
  const double x1[3] = {0, 1, 2};
  ps = mp_particles(ctx, 1, 3, x1, 0.3);
  assert_ok(ctx, mfree_mesh_create(ctx, ps, &m));
  const int32_t tri[3] = {0, 1, 2};
  assert_error(ctx, mfree_mesh_add_elements(m, MFREE_ELEMENT_TRI3, 1, tri, 0, MFREE_COPY), MFREE_ERR_MISMATCH,
               "mixed dimension");
  mfree_mesh_destroy(&m);
  mfree_particles_destroy(&ps);
}

/* Inverted or degenerate element: mesh setup and approximant setup both refuse it. */
static void bad_element(int dim, int32_t n, const double *x, mfree_element_t type, const int32_t *conn,
                        const char *needle) {
  mfree_particles_t *ps = mp_particles(ctx, dim, n, x, 0.2);
  mfree_mesh_t *m = mp_mesh(ctx, ps, type, 1, conn);
  assert_error(ctx, mfree_mesh_setup(m), MFREE_ERR_INPUT, needle);
  mfree_approximant_t *a = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MPFEM, &a));
  assert_ok(ctx, mfree_approximant_set_mesh(a, m));
  assert_error(ctx, mfree_approximant_setup(a), MFREE_ERR_INPUT, needle);
  int32_t npts = 0;
  assert_error(ctx, mfree_mesh_get_quadrature(m, 2, &npts, NULL, NULL), MFREE_ERR_INPUT, needle);
  mfree_approximant_destroy(&a);
  mfree_mesh_destroy(&m);
  mfree_particles_destroy(&ps);
}

static void test_jacobians(void **state) {
  (void)state;
  const double x1[2] = {1.0, 0.0};
  const int32_t l[2] = {0, 1};
  bad_element(1, 2, x1, MFREE_ELEMENT_LINE2, l, "inverted");
  const double xt[6] = {0, 0, 1, 0, 0, 1};
  const int32_t cw[3] = {0, 2, 1};
  bad_element(2, 3, xt, MFREE_ELEMENT_TRI3, cw, "inverted");
  const double xc[6] = {0, 0, 1, 1, 2, 2}; /* collinear */
  const int32_t t[3] = {0, 1, 2};
  bad_element(2, 3, xc, MFREE_ELEMENT_TRI3, t, "degenerate");
  const double xq[8] = {0, 0, 2, 0, 0.5, 0.5, 0, 2}; /* dart: re-entrant corner 2 */
  const int32_t q[4] = {0, 1, 2, 3};
  bad_element(2, 4, xq, MFREE_ELEMENT_QUAD4, q, "corner 2");
  const double xd[8] = {1, 0, 0, 1, -1, 0, 0, -1}; /* diamond: xy = 0 at every node */
  const int32_t d[4] = {3, 0, 1, 2};
  bad_element(2, 4, xd, MFREE_ELEMENT_QUAD4, d, "singular general shape functions");
}

static void test_support_reaches_no_element(void **state) {
  (void)state;
  const double x[4] = {0.0, 1.0, 2.0, 5.0}; /* particle 3 belongs to no element */
  const int32_t conn[4] = {0, 1, 1, 2};
  mfree_particles_t *ps = mp_particles(ctx, 1, 4, x, 0.5);
  mfree_mesh_t *m = mp_mesh(ctx, ps, MFREE_ELEMENT_LINE2, 2, conn);
  mfree_status_t st;
  mfree_approximant_t *a = mp_approx(ctx, ps, m, MFREE_KERNEL_COSINE, MFREE_MPFEM_DERIV_FULL,
                                     MFREE_DERIV_VALUE, 0, NULL, 0, &st);
  assert_int_equal(st, MFREE_FAIL_NEIGHBORS);
  char msg[512];
  assert_ok(ctx, mfree_context_get_last_error(ctx, NULL, msg, sizeof msg));
  assert_non_null(strstr(msg, "reaches no element"));
  int32_t status[4], nfailed = 0;
  assert_ok(ctx, mfree_approximant_get_site_status(a, status, &nfailed));
  assert_int_equal(nfailed, 1);
  assert_int_equal(status[3], MFREE_FAIL_NEIGHBORS);
  int64_t rp[5];
  assert_ok(ctx, mfree_approximant_assemble_csr(a, MFREE_DERIV_VALUE, 0, rp, NULL, NULL));
  assert_int_equal(rp[4] - rp[3], 0);
  mfree_approximant_destroy(&a);
  /* host points: one outside the mesh beyond the support, one inside */
  const double pts[2] = {3.0, 1.5};
  a = mp_approx(ctx, ps, m, MFREE_KERNEL_COSINE, MFREE_MPFEM_DERIV_FULL, MFREE_DERIV_VALUE, 2, pts, 0.5, &st);
  assert_int_equal(st, MFREE_FAIL_NEIGHBORS);
  assert_ok(ctx, mfree_approximant_get_site_status(a, status, &nfailed));
  assert_int_equal(nfailed, 1);
  assert_int_equal(status[0], MFREE_FAIL_NEIGHBORS);
  assert_int_equal(status[1], 0);
  mfree_approximant_destroy(&a);
  mfree_mesh_destroy(&m);
  mfree_particles_destroy(&ps);
}

static void test_misuse(void **state) {
  (void)state;
  const double x[3] = {0, 1, 2};
  const int32_t conn[4] = {0, 1, 1, 2};
  mfree_particles_t *ps = mp_particles(ctx, 1, 3, x, 0.5), *other = mp_particles(ctx, 1, 3, x, 0.5);
  mfree_mesh_t *m = mp_mesh(ctx, ps, MFREE_ELEMENT_LINE2, 2, conn);
  mfree_mesh_t *mo = mp_mesh(ctx, other, MFREE_ELEMENT_LINE2, 2, conn);
  mfree_approximant_t *a = NULL, *mls = NULL;
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MPFEM, &a));
  assert_error(ctx, mfree_approximant_setup(a), MFREE_ERR_STATE, "mesh");
  assert_error(ctx, mfree_approximant_set_mesh(a, mo), MFREE_ERR_MISMATCH, "another particle set");
  assert_error(ctx, mfree_approximant_set_mesh(a, NULL), MFREE_ERR_NULL, "NULL");
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MLS, &mls));
  assert_error(ctx, mfree_approximant_set_mesh(mls, m), MFREE_ERR_UNSUPPORTED, "MPFEM");
  assert_error(ctx, mfree_approximant_set_mpfem(mls, MFREE_MPFEM_DERIV_FULL, 8), MFREE_ERR_UNSUPPORTED, "MPFEM");
  assert_ok(ctx, mfree_approximant_set_mesh(a, m));
  assert_error(ctx, mfree_approximant_set_order(a, 2), MFREE_ERR_UNSUPPORTED, "order 1");
  assert_ok(ctx, mfree_approximant_set_order(a, 1));
  assert_error(ctx, mfree_approximant_set_mpfem(a, (mfree_mpfem_deriv_t)4, 8), MFREE_ERR_ARG, "derivative");
  assert_error(ctx, mfree_approximant_set_mpfem(a, MFREE_MPFEM_DERIV_FULL, 0), MFREE_ERR_ARG, "ngauss");
  assert_error(ctx, mfree_approximant_set_mpfem(a, MFREE_MPFEM_DERIV_FULL, 21), MFREE_ERR_ARG, "ngauss");
  /* the nodal scheme at host points */
  const double p = 0.5, hp = 0.5;
  assert_ok(ctx, mfree_approximant_set_mpfem(a, MFREE_MPFEM_DERIV_NODAL, 8));
  assert_ok(ctx, mfree_approximant_set_points(a, 1, &p, MFREE_LAYOUT_AOS, 1, &hp, 0, MFREE_COPY));
  assert_error(ctx, mfree_approximant_setup(a), MFREE_ERR_UNSUPPORTED, "nodes only");
  /* Hessians of eq 21 need a continuous kernel */
  assert_ok(ctx, mfree_approximant_set_mpfem(a, MFREE_MPFEM_DERIV_FULL, 8));
  assert_ok(ctx, mfree_approximant_set_kernel(a, MFREE_KERNEL_HAAR, 0.0));
  assert_ok(ctx, mfree_approximant_set_derivatives(a, MFREE_DERIV_VALUE | MFREE_DERIV_HESSIAN));
  assert_error(ctx, mfree_approximant_setup(a), MFREE_ERR_UNSUPPORTED, "Haar");
  assert_ok(ctx, mfree_approximant_set_mpfem(a, MFREE_MPFEM_DERIV_ASSUMED_STRAIN, 8));
  assert_ok(ctx, mfree_approximant_setup(a));
  int32_t npts = 0;
  assert_error(ctx, mfree_mesh_get_quadrature(m, 11, &npts, NULL, NULL), MFREE_ERR_ARG, "ngauss");
  assert_error(ctx, mfree_mesh_get_quadrature(m, 2, NULL, NULL, NULL), MFREE_ERR_NULL, "npts");
  mfree_approximant_destroy(&a);
  mfree_approximant_destroy(&mls);
  mfree_mesh_destroy(&m);
  mfree_mesh_destroy(&mo);
  mfree_particles_destroy(&ps);
  mfree_particles_destroy(&other);

  /* HEX8 that is not an axis-aligned brick: a valid mesh, but no MPFEM weights */
  double x3[24];
  for (int k = 0; k < 8; ++k) {
    x3[3 * k] = (k == 1 || k == 2 || k == 5 || k == 6) ? 1.0 : 0.0;
    x3[3 * k + 1] = (k == 2 || k == 3 || k == 6 || k == 7) ? 1.0 : 0.0;
    x3[3 * k + 2] = k >= 4 ? 1.0 : 0.0;
  }
  x3[3 * 6] = 1.3; /* stretch one corner */
  const int32_t h8[8] = {0, 1, 2, 3, 4, 5, 6, 7};
  ps = mp_particles(ctx, 3, 8, x3, 0.2);
  m = mp_mesh(ctx, ps, MFREE_ELEMENT_HEX8, 1, h8);
  assert_ok(ctx, mfree_mesh_setup(m));
  assert_ok(ctx, mfree_approximant_create(ctx, ps, MFREE_METHOD_MPFEM, &a));
  assert_ok(ctx, mfree_approximant_set_mesh(a, m));
  assert_error(ctx, mfree_approximant_setup(a), MFREE_ERR_UNSUPPORTED, "bricks");
  mfree_approximant_destroy(&a);
  mfree_mesh_destroy(&m);
  mfree_particles_destroy(&ps);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_connectivity),
      cmocka_unit_test(test_jacobians),
      cmocka_unit_test(test_support_reaches_no_element),
      cmocka_unit_test(test_misuse),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
