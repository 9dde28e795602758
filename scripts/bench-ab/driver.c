/* The driver of scripts/bench-ab.sh.
 *   driver OLD.so NEW.so ROUNDS CASE...   both copies of case.c, each in its own link-map
 *                                         namespace (dlmopen: each loads its own libmfree of
 *                                         the same soname), one warm-up each, then ROUNDS
 *                                         iterations of each alternating (old, new | new,
 *                                         old | ...), so that both sides see the same moments
 *                                         of a shared machine; prints the best and median of
 *                                         each, their ratios, the median of the per-round
 *                                         ratios and the minor page faults per iteration.
 *   driver ONE.so ROUNDS CASE...          one copy: a warm-up and ROUNDS iterations (for
 *                                         valgrind --toggle-collect=ab_iter). */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

typedef int (*init_fn)(int, char **);
typedef double (*iter_fn)(void);
typedef const double *(*parts_fn)(void);

typedef struct {
  init_fn init;
  iter_fn iter;
  parts_fn parts;
} side_t;

static side_t load(const char *path, int own_namespace) {
  void *h = own_namespace ? dlmopen(LM_ID_NEWLM, path, RTLD_NOW | RTLD_LOCAL) : dlopen(path, RTLD_NOW | RTLD_LOCAL);
  if (!h) {
    fprintf(stderr, "bench-ab: %s\n", dlerror());
    exit(1);
  }
  side_t s;
  s.init = (init_fn)dlsym(h, "ab_init");
  s.iter = (iter_fn)dlsym(h, "ab_iter");
  s.parts = (parts_fn)dlsym(h, "ab_parts");
  if (!s.init || !s.iter || !s.parts) {
    fprintf(stderr, "bench-ab: %s lacks ab_init, ab_iter or ab_parts\n", path);
    exit(1);
  }
  return s;
}

static long faults(void) {
  struct rusage u;
  getrusage(RUSAGE_SELF, &u);
  return u.ru_minflt + u.ru_majflt;
}

static int cmp(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}
static double median(const double *v, int n) {
  double *c = malloc(sizeof *c * n);
  memcpy(c, v, sizeof *c * n);
  qsort(c, n, sizeof *c, cmp);
  const double m = n % 2 ? c[n / 2] : 0.5 * (c[n / 2 - 1] + c[n / 2]);
  free(c);
  return m;
}
static double best(const double *v, int n) {
  double m = v[0];
  for (int i = 1; i < n; ++i)
    if (v[i] < m) m = v[i];
  return m;
}

int main(int argc, char **argv) {
  if (argc >= 4 && strstr(argv[2], ".so") == NULL) {  /* one side */
    side_t s = load(argv[1], 0);
    const int rounds = atoi(argv[2]);
    s.init(argc - 3, argv + 3);
    s.iter();
    double b = 1e300;
    for (int r = 0; r < rounds; ++r) {
      const double t = s.iter();
      if (t < b) b = t;
    }
    printf("best %.6f s\n", b);
    return 0;
  }
  if (argc < 5) {
    fprintf(stderr, "usage: driver OLD.so NEW.so ROUNDS CASE... | driver ONE.so ROUNDS CASE...\n");
    return 2;
  }
  const int rounds = atoi(argv[3]);
  if (rounds < 1) {
    fprintf(stderr, "bench-ab: ROUNDS must be positive\n");
    return 2;
  }
  side_t s[2] = {load(argv[1], 1), load(argv[2], 1)};
  for (int k = 0; k < 2; ++k) s[k].init(argc - 4, argv + 4);
  for (int k = 0; k < 2; ++k) s[k].iter(); /* warm-up: first allocations */
  double *t[2], *p[2][3], *ratio = malloc(sizeof(double) * rounds);
  long flt[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    t[k] = malloc(sizeof(double) * rounds);
    for (int q = 0; q < 3; ++q) p[k][q] = malloc(sizeof(double) * rounds);
  }
  for (int r = 0; r < rounds; ++r) {
    for (int o = 0; o < 2; ++o) {
      const int k = (r & 1) ? 1 - o : o;
      const long f0 = faults();
      t[k][r] = s[k].iter();
      flt[k] += faults() - f0;
      const double *pp = s[k].parts();
      for (int q = 0; q < 3; ++q) p[k][q][r] = pp[q];
    }
    ratio[r] = t[1][r] / t[0][r];
  }
  char label[256] = "";
  for (int a = 4; a < argc; ++a) {
    strncat(label, argv[a], sizeof label - strlen(label) - 2);
    if (a + 1 < argc) strcat(label, " ");
  }
  printf("| %s | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %ld / %ld |", label,
         1e3 * best(t[0], rounds), 1e3 * best(t[1], rounds), best(t[1], rounds) / best(t[0], rounds),
         1e3 * median(t[0], rounds), 1e3 * median(t[1], rounds),
         median(t[1], rounds) / median(t[0], rounds), median(ratio, rounds), flt[0] / rounds,
         flt[1] / rounds);
  if (p[0][1][0] > 0) { /* the pairs case: rows, tables, pair gradients, best over best */
    printf(" parts");
    for (int q = 0; q < 3; ++q) printf(" %.3f", best(p[1][q], rounds) / best(p[0][q], rounds));
  }
  printf("\n");
  return 0;
}
