/* Times functions of a CasADi-generated shared library from C, as bench_native times ours:
 * the same state, batches of calls about 2 ms long, the median of up to 51 batches (at most
 * about 2 s per function), no Python and no allocation in the loop. Outputs go to buffers
 * sized from the functions' own sparsity (the nonzeros, CasADi's sparse format).
 *
 * usage: casadi_timer LIB.so NX [--np=NP] NAME... < state [params]   (NX numbers on stdin, then
 *        NP parameter values when the functions take the parameters as their second input)
 * prints one JSON object {"NAME": seconds per call, ...}
 */
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef long long int casadi_int;
typedef int (*eval_t)(const double **, double **, casadi_int *, double *, int);
typedef int (*work_t)(casadi_int *, casadi_int *, casadi_int *, casadi_int *);
typedef const casadi_int *(*sparsity_t)(casadi_int);
typedef casadi_int (*count_t)(void);

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static int cmp(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void *sym(void *lib, const char *name, const char *suffix) {
    char buf[256];
    snprintf(buf, sizeof buf, "%s%s", name, suffix);
    void *s = dlsym(lib, buf);
    if (!s) {
        fprintf(stderr, "casadi_timer: no symbol %s\n", buf);
        exit(2);
    }
    return s;
}

static double time_function(void *lib, const char *name, const double *z, const double *pv) {
    eval_t eval = (eval_t)sym(lib, name, "");
    work_t work = (work_t)sym(lib, name, "_work");
    sparsity_t sp_out = (sparsity_t)sym(lib, name, "_sparsity_out");
    count_t n_out = (count_t)sym(lib, name, "_n_out");
    casadi_int sz_arg, sz_res, sz_iw, sz_w;
    work(&sz_arg, &sz_res, &sz_iw, &sz_w);
    const double **arg = calloc(sz_arg + 1, sizeof *arg);
    double **res = calloc(sz_res + 1, sizeof *res);
    casadi_int *iw = calloc(sz_iw + 1, sizeof *iw);
    double *w = calloc(sz_w + 1, sizeof *w);
    arg[0] = z;
    if (pv) arg[1] = pv; /* the parameters, when the functions take them as an input */
    for (casadi_int i = 0; i < n_out(); i++) {
        const casadi_int *sp = sp_out(i);
        /* compressed form: {nrow, ncol, 1} is dense; else {nrow, ncol, colind (from 0), row} */
        casadi_int ncol = sp[1], nnz = sp[2] ? sp[0] * ncol : sp[2 + ncol];
        res[i] = calloc(nnz + 1, sizeof(double));
    }
    /* warm up for 0.2 s first: the first tens of milliseconds of a busy core run slower on
       this VM (up to 1.5x, from one process to the next), as bench_native's do */
    double w0 = now();
    while (now() - w0 < 0.2) eval(arg, res, iw, w, 0);
    /* calibrate: batches of k calls about 2 ms long */
    double t0 = now();
    eval(arg, res, iw, w, 0);
    double one = now() - t0;
    if (one < 1e-9) one = 1e-9;
    long k = (long)(2e-3 / one) + 1;
    long reps = (long)(2.0 / (one * k));
    if (reps > 51) reps = 51;
    if (reps < 1) reps = 1;
    double *v = malloc(reps * sizeof *v);
    for (long r = 0; r < reps; r++) {
        double t = now();
        for (long i = 0; i < k; i++) eval(arg, res, iw, w, 0);
        v[r] = (now() - t) / k;
    }
    qsort(v, reps, sizeof *v, cmp);
    double med = reps % 2 ? v[reps / 2] : 0.5 * (v[reps / 2 - 1] + v[reps / 2]);
    free(v);
    return med;
}

int main(int argc, char **argv) {
    if (argc < 4) {
        fprintf(stderr, "usage: casadi_timer LIB.so NX NAME... < state\n");
        return 2;
    }
    /* the generated code calls libm (tanh, sqrt) but is not linked against it */
    if (!dlopen("libm.so.6", RTLD_NOW | RTLD_GLOBAL)) {
        fprintf(stderr, "casadi_timer: %s\n", dlerror());
        return 2;
    }
    void *lib = dlopen(argv[1], RTLD_NOW);
    if (!lib) {
        fprintf(stderr, "casadi_timer: %s\n", dlerror());
        return 2;
    }
    int nx = atoi(argv[2]);
    /* `--np=NP` before the names: the functions' second input, NP numbers after the state */
    int first = 3, np = 0;
    if (strncmp(argv[3], "--np=", 5) == 0) {
        np = atoi(argv[3] + 5);
        first = 4;
    }
    double *z = malloc((nx + 1) * sizeof *z);
    for (int i = 0; i < nx; i++) {
        if (scanf("%lf", &z[i]) != 1) {
            fprintf(stderr, "casadi_timer: expected %d state values on stdin\n", nx);
            return 2;
        }
    }
    double *pv = NULL;
    if (np > 0) {
        pv = malloc((np + 1) * sizeof *pv);
        for (int i = 0; i < np; i++) {
            if (scanf("%lf", &pv[i]) != 1) {
                fprintf(stderr, "casadi_timer: expected %d parameter values after the state\n", np);
                return 2;
            }
        }
    }
    printf("{");
    for (int a = first; a < argc; a++) {
        printf("%s\"%s\": %.6e", a > first ? ", " : "", argv[a], time_function(lib, argv[a], z, pv));
        fflush(stdout);
    }
    printf("}\n");
    return 0;
}
