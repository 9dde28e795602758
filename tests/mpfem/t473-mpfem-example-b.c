/* Paper 004 Example B (Sect. 3.2, Figs. 5-6), see mpfem_exampleb.h, at the spacings
 * h = 0.1, 0.05, 0.02, 0.01, 0.005, 0.002 (the paper: 0.1 down to 0.002).
 *  - The reproduced values (docs/papers.md, paper 004, reproduction: cosine kernel, d = 2h,
 *    eq 21 stiffness, 3 Gauss points per element): FEM L2/H1 and MPFEM L2/H1(22)/H1(21) to 1e-3
 *    relative at every spacing.
 *  - The paper's claims (Sect. 3.2): L2 rate 2 +- 0.15 for both methods, MPFEM H1 rate
 *    (eq 22) in [1.5, 2], FEM H1 rate about 1 (0.9..1.1), all on the last pair of
 *    spacings (the coarse meshes do not resolve the bump of width 0.02 and give
 *    pre-asymptotic rates); MPFEM L2 below FEM's at every spacing. With 3 Gauss points
 *    the load quadrature error dominates at h = 0.1 and 0.05 (the bump is sampled by 3
 *    points), where the MPFEM error is then above FEM's (26.054 vs 26.031 and 0.373 vs
 *    0.349 in the reproduced values too), so the ordering is checked with 6
 *    points per element, within the paper's 1..6.
 * The fine meshes are slow in unoptimised builds only in proportion (a few seconds). */
#include <mfree_suitesparse.h>

#include "mpfem_exampleb.h"

#define NH 6
static const double kH[NH] = {0.1, 0.05, 0.02, 0.01, 0.005, 0.002};
/* docs/papers.md, paper 004, reproduction */
static const double kFemL2[NH] = {2.6031e+01, 3.4942e-01, 1.9598e-02, 6.0914e-03, 1.5540e-03, 2.5006e-04};
static const double kFemH1[NH] = {4.4307e+01, 4.8816e+00, 3.2336e+00, 1.9387e+00, 9.8441e-01, 3.9548e-01};
static const double kMpL2[NH] = {2.6054e+01, 3.7278e-01, 8.3050e-03, 1.1168e-03, 1.3590e-04, 2.0602e-05};
static const double kMpH21[NH] = {4.5014e+01, 5.1972e+00, 1.3931e+00, 5.4924e-01, 1.7890e-01, 6.5482e-02};
static const double kMpH22[NH] = {4.4049e+01, 6.4039e+00, 3.2426e+00, 1.1988e+00, 3.4679e-01, 6.1361e-02};

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

static int32_t nodes(int i) { return (int32_t)lround(1.0 / kH[i]) + 1; }

static void near(const char *what, int i, double got, double ref, double rel) {
  print_message("  h = %-6g %-10s %.4e  (reproduced: %.4e)\n", kH[i], what, got, ref);
  if (!(fabs(got - ref) <= rel * ref))
    fail_msg("h = %g %s: %.5e differs from the reproduced %.4e by more than %g relative", kH[i], what, got, ref, rel);
}

static void test_reference_table(void **state) {
  (void)state;
  for (int i = 0; i < NH; ++i) {
    eb_err_t fe, mp;
    eb_fem(ctx, nodes(i), 3, &fe);
    assert_int_equal(eb_mpfem(ctx, nodes(i), 3, MFREE_KERNEL_COSINE, kH[i], MFREE_MPFEM_DERIV_FULL, &mp, NULL),
                     MFREE_SUCCESS);
    near("FEM L2", i, fe.L2, kFemL2[i], 1e-3);
    near("FEM H1", i, fe.H1, kFemH1[i], 1e-3);
    near("MPFEM L2", i, mp.L2, kMpL2[i], 1e-3);
    near("MPFEM H1(22)", i, mp.H1, kMpH22[i], 1e-3);
    near("MPFEM H1(21)", i, mp.H1_21, kMpH21[i], 1e-3);
  }
}

static double rate(double e0, double e1, double h0, double h1) { return log(e0 / e1) / log(h0 / h1); }

static void test_paper_claims(void **state) {
  (void)state;
  eb_err_t fe[NH], mp[NH];
  for (int i = 0; i < NH; ++i) {
    eb_fem(ctx, nodes(i), 6, &fe[i]);
    assert_int_equal(eb_mpfem(ctx, nodes(i), 6, MFREE_KERNEL_COSINE, kH[i], MFREE_MPFEM_DERIV_FULL, &mp[i], NULL),
                     MFREE_SUCCESS);
    print_message("  h = %-6g FEM L2 %.4e H1 %.4e | MPFEM L2 %.4e H1(22) %.4e\n", kH[i], fe[i].L2, fe[i].H1,
                  mp[i].L2, mp[i].H1);
    if (!(mp[i].L2 < fe[i].L2)) fail_msg("h = %g: MPFEM L2 %.4e is not below FEM's %.4e", kH[i], mp[i].L2, fe[i].L2);
  }
  const int a = NH - 2, b = NH - 1;
  const double rfl2 = rate(fe[a].L2, fe[b].L2, kH[a], kH[b]), rml2 = rate(mp[a].L2, mp[b].L2, kH[a], kH[b]);
  const double rfh1 = rate(fe[a].H1, fe[b].H1, kH[a], kH[b]), rmh1 = rate(mp[a].H1, mp[b].H1, kH[a], kH[b]);
  print_message("  rates (h = 0.005 -> 0.002): FEM L2 %.3f H1 %.3f, MPFEM L2 %.3f H1(22) %.3f\n", rfl2, rfh1, rml2, rmh1);
  assert_true(fabs(rfl2 - 2.0) <= 0.15);
  assert_true(fabs(rml2 - 2.0) <= 0.15);
  assert_true(rmh1 >= 1.5 && rmh1 <= 2.0);
  assert_true(fabs(rfh1 - 1.0) <= 0.1);
  assert_true(mp[b].H1 < fe[b].H1);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_reference_table),
      cmocka_unit_test(test_paper_claims),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
