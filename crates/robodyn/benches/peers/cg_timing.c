/* Generated code, side by side: Pinocchio + CppADCodeGen against robodyn's `generate --lang c`
 * (driven by codegen.py; NOT run by CI). Linked with, for one robot:
 *   cg_rnea(x, y), cg_crba(x, y), cg_aba(x, y), cg_drnea(x, y)   wrappers of CppADCodeGen's
 *     forward_zero functions (drnea: computeRNEADerivatives traced), cg_jrnea(x, y) of its
 *     jacobian function (CppAD's Jacobian of rnea, nv x 3 nv row-major)
 *   rd_idm(q, qd, qdd, out), rd_inertia(q, out), rd_ddm(q, qd, gam, out),
 *   rd_idm_derivatives(q, qd, qdd, out)   robodyn's
 * every generated function in its own translation unit, all compiled with the same flags.
 *
 *   cg_timing STATES RESULTS [samples] [target_us]
 *
 * STATES (written by codegen.py): `nv nl n_states`, then nv robodyn indices (joint k of
 * Pinocchio's order is entry idx[k] of robodyn's NL-vectors), nv ranks (its position among
 * robodyn's movable joints, the order of the generated outputs), then n_states lines q v a tau
 * in Pinocchio's order. RESULTS: per state, lines `<side>_<algo> values` with rnea tau, the full
 * inertia matrix row by row, ddq and the derivatives [dtau_dq, dtau_dv, dtau_da] each row by row,
 * all in Pinocchio's order (dtau_da from its upper triangle: Pinocchio fills only that one). Prints `time <name> <median ns>`. */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

void cg_rnea(const double *x, double *y);
void cg_crba(const double *x, double *y);
void cg_aba(const double *x, double *y);
void cg_drnea(const double *x, double *y);
void cg_jrnea(const double *x, double *y);
void rd_idm(const double *q, const double *qd, const double *qdd, double *out);
void rd_inertia(const double *q, double *out);
void rd_ddm(const double *q, const double *qd, const double *gam, double *out);
void rd_idm_derivatives(const double *q, const double *qd, const double *qdd, double *out);

static int nv, nl, ns;
static int *idx, *rank_;
/* per state: Pinocchio inputs [q v a] and [q v tau]; robodyn q, qd, qdd, tau (NL each) */
static double *x_rnea, *x_aba, *rq, *rqd, *rqdd, *rtau, *y, *out;
static volatile double sink;

static double now_ns(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec * 1e9 + (double)t.tv_nsec;
}

static void read_states(const char *path) {
  FILE *f = fopen(path, "r");
  if (!f || fscanf(f, "%d %d %d", &nv, &nl, &ns) != 3) {
    fprintf(stderr, "cannot read %s\n", path);
    exit(2);
  }
  idx = malloc(sizeof(int) * nv);
  rank_ = malloc(sizeof(int) * nv);
  for (int k = 0; k < nv; ++k)
    if (fscanf(f, "%d", &idx[k]) != 1) exit(2);
  for (int k = 0; k < nv; ++k)
    if (fscanf(f, "%d", &rank_[k]) != 1) exit(2);
  x_rnea = calloc((size_t)ns * 3 * nv, sizeof(double));
  x_aba = calloc((size_t)ns * 3 * nv, sizeof(double));
  rq = calloc((size_t)ns * nl, sizeof(double));
  rqd = calloc((size_t)ns * nl, sizeof(double));
  rqdd = calloc((size_t)ns * nl, sizeof(double));
  rtau = calloc((size_t)ns * nl, sizeof(double));
  y = calloc((size_t)3 * nv * nv, sizeof(double));
  out = calloc((size_t)3 * nv * nv, sizeof(double));
  for (int s = 0; s < ns; ++s) {
    double v[4][nv];
    for (int part = 0; part < 4; ++part)
      for (int k = 0; k < nv; ++k)
        if (fscanf(f, "%lf", &v[part][k]) != 1) exit(2);
    for (int k = 0; k < nv; ++k) {
      x_rnea[s * 3 * nv + k] = x_aba[s * 3 * nv + k] = v[0][k];
      x_rnea[s * 3 * nv + nv + k] = x_aba[s * 3 * nv + nv + k] = v[1][k];
      x_rnea[s * 3 * nv + 2 * nv + k] = v[2][k];
      x_aba[s * 3 * nv + 2 * nv + k] = v[3][k];
      rq[s * nl + idx[k]] = v[0][k];
      rqd[s * nl + idx[k]] = v[1][k];
      rqdd[s * nl + idx[k]] = v[2][k];
      rtau[s * nl + idx[k]] = v[3][k];
    }
  }
  fclose(f);
}

static void put(FILE *f, const char *tag, const double *v, int n) {
  fprintf(f, "%s", tag);
  for (int k = 0; k < n; ++k) fprintf(f, " %.17g", v[k]);
  fputc('\n', f);
}

/* position of M(i, j) (Pinocchio order) in CppADCodeGen's upper triangle, row by row */
static int upper(int i, int j) {
  if (i > j) { int t = i; i = j; j = t; }
  return i * nv - i * (i - 1) / 2 + (j - i);
}

/* position of A(i, j) (Pinocchio order) in robodyn's lower triangle, row by row (movable ranks) */
static int lower(int i, int j) {
  int r = rank_[i], c = rank_[j];
  if (r < c) { int t = r; r = c; c = t; }
  return r * (r + 1) / 2 + c;
}

static void write_results(const char *path) {
  FILE *f = fopen(path, "w");
  double *m = malloc(sizeof(double) * 3 * nv * nv), *v = malloc(sizeof(double) * nv);
  for (int s = 0; s < ns; ++s) {
    const double *q = rq + s * nl, *qd = rqd + s * nl;
    cg_rnea(x_rnea + s * 3 * nv, y);
    put(f, "cg_rnea", y, nv);
    rd_idm(q, qd, rqdd + s * nl, out);
    for (int k = 0; k < nv; ++k) v[k] = out[rank_[k]];
    put(f, "rd_rnea", v, nv);
    cg_crba(x_rnea + s * 3 * nv, y);
    for (int i = 0; i < nv; ++i)
      for (int j = 0; j < nv; ++j) m[i * nv + j] = y[upper(i, j)];
    put(f, "cg_crba", m, nv * nv);
    rd_inertia(q, out);
    for (int i = 0; i < nv; ++i)
      for (int j = 0; j < nv; ++j) m[i * nv + j] = out[lower(i, j)];
    put(f, "rd_crba", m, nv * nv);
    cg_aba(x_aba + s * 3 * nv, y);
    put(f, "cg_aba", y, nv);
    rd_ddm(q, qd, rtau + s * nl, out);
    for (int k = 0; k < nv; ++k) v[k] = out[rank_[k]];
    put(f, "rd_ddm", v, nv);
    /* derivatives: CppADCodeGen's blocks row-major; robodyn's column-major in its joint order */
    cg_drnea(x_rnea + s * 3 * nv, y);
    for (int b = 0; b < 3; ++b)
      for (int i = 0; i < nv; ++i)
        for (int j = 0; j < nv; ++j) {
          int r = b == 2 && i > j ? j : i, c = b == 2 && i > j ? i : j;
          m[b * nv * nv + i * nv + j] = y[b * nv * nv + r * nv + c];
        }
    put(f, "cg_drnea", m, 3 * nv * nv);
    /* CppAD's Jacobian: row i = d tau_i / d[q v a] */
    cg_jrnea(x_rnea + s * 3 * nv, y);
    for (int b = 0; b < 3; ++b)
      for (int i = 0; i < nv; ++i)
        for (int j = 0; j < nv; ++j) m[b * nv * nv + i * nv + j] = y[i * 3 * nv + b * nv + j];
    put(f, "cg_jrnea", m, 3 * nv * nv);
    rd_idm_derivatives(q, qd, rqdd + s * nl, out);
    for (int b = 0; b < 3; ++b)
      for (int i = 0; i < nv; ++i)
        for (int j = 0; j < nv; ++j)
          m[b * nv * nv + i * nv + j] = out[b * nv * nv + rank_[j] * nv + rank_[i]];
    put(f, "rd_drnea", m, 3 * nv * nv);
  }
  fclose(f);
  free(m);
  free(v);
}

static int cmp(const void *a, const void *b) {
  double d = *(const double *)a - *(const double *)b;
  return (d > 0) - (d < 0);
}

#define PASS(call)                        \
  for (int s = 0; s < ns; ++s) {          \
    call;                                 \
    sink += out[0] + y[0];                \
  }

#define TIME(name, call)                                                    \
  do {                                                                      \
    PASS(call);                                                             \
    double t0 = now_ns();                                                   \
    PASS(call);                                                             \
    double one = (now_ns() - t0) / 1e3;                                     \
    int reps = (int)(target_us / (one > 1e-3 ? one : 1e-3));                \
    if (reps < 1) reps = 1;                                                 \
    double ts[samples];                                                     \
    for (int k = 0; k < samples; ++k) {                                     \
      double a = now_ns();                                                  \
      for (int r = 0; r < reps; ++r) PASS(call);                            \
      ts[k] = (now_ns() - a) / ((double)reps * ns);                         \
    }                                                                       \
    qsort(ts, (size_t)samples, sizeof(double), cmp);                        \
    printf("time %s %.1f\n", name, ts[samples / 2]);                        \
  } while (0)

int main(int argc, char **argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: cg_timing STATES RESULTS [samples] [target_us]\n");
    return 2;
  }
  int samples = argc > 3 ? atoi(argv[3]) : 21;
  double target_us = argc > 4 ? atof(argv[4]) : 400.0;
  read_states(argv[1]);
  write_results(argv[2]);
  TIME("cg_rnea", cg_rnea(x_rnea + s * 3 * nv, y));
  TIME("rd_idm_c", rd_idm(rq + s * nl, rqd + s * nl, rqdd + s * nl, out));
  TIME("cg_crba", cg_crba(x_rnea + s * 3 * nv, y));
  TIME("rd_inertia_c", rd_inertia(rq + s * nl, out));
  TIME("cg_aba", cg_aba(x_aba + s * 3 * nv, y));
  TIME("rd_ddm_c", rd_ddm(rq + s * nl, rqd + s * nl, rtau + s * nl, out));
  TIME("cg_drnea", cg_drnea(x_rnea + s * 3 * nv, y));
  TIME("cg_jrnea", cg_jrnea(x_rnea + s * 3 * nv, y));
  TIME("rd_idm_derivatives_c", rd_idm_derivatives(rq + s * nl, rqd + s * nl, rqdd + s * nl, out));
  return 0;
}
