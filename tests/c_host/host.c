/* A minimal FMI 2.0 co-simulation host in C, with no Python in its process (tests only).

   host LIBRARY RESOURCES_URI GUID SCENARIO [one-by-one]

   SCENARIO (text): "dt n_steps", then "parameters K" and K lines "vr R|B value" set during
   initialisation, then the inputs, then "outputs P vr...", then the input values:
   - "inputs M vr...": n_steps rows of M values ("nan" for a missing one), row k set before step k;
   - "table M R" and M pairs "vr c|d": R rows "time v1..vM" of an input file, applied as
     Reference-FMUs' fmusim applies one (fmusim_input.c): at each communication point t, and
     at t = 0 during initialisation, row r is the last with time <= t; a continuous (c) input
     gets v_r + (t - t_r) (v_r+1 - v_r) / (t_r+1 - t_r), a discrete (d) one v_r (held).
   Prints one row of P outputs (%.17g) after each step, read in one fmi2GetReal, or one call
   per value with "one-by-one" (as the FMI Compliance Checker reads them), and, last on
   stderr, "stepping S s": the time of the step loop (benchmarks/bench_fmu_calls.py).
   Exits 1 on any status other than fmi2OK, naming the call. */
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fmi2.h"

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...) {
    va_list args;
    (void)env;
    va_start(args, message);
    fprintf(stderr, "[%s %d %s] ", name, (int)status, category);
    vfprintf(stderr, message, args);
    fputc('\n', stderr);
    va_end(args);
}

static void *symbol(void *library, const char *name) {
    void *f = dlsym(library, name);
    if (!f) {
        fprintf(stderr, "no symbol %s\n", name);
        exit(1);
    }
    return f;
}

#define CHECK(call)                                         \
    if ((call) != fmi2OK) {                                 \
        fprintf(stderr, "%s did not return fmi2OK\n", #call); \
        exit(1);                                            \
    }

typedef fmi2Component (*Instantiate)(fmi2String, fmi2Type, fmi2String, fmi2String, const fmi2CallbackFunctions *,
                                     fmi2Boolean, fmi2Boolean);
typedef fmi2Status (*Setup)(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real, fmi2Boolean, fmi2Real);
typedef fmi2Status (*Call)(fmi2Component);
typedef fmi2Status (*SetReal)(fmi2Component, const fmi2ValueReference *, size_t, const fmi2Real *);
typedef fmi2Status (*GetReal)(fmi2Component, const fmi2ValueReference *, size_t, fmi2Real *);
typedef fmi2Status (*SetBoolean)(fmi2Component, const fmi2ValueReference *, size_t, const fmi2Boolean *);
typedef fmi2Status (*DoStep)(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean);
typedef void (*Free)(fmi2Component);

/* An input file (the "table" scenario). */
typedef struct {
    int n, rows;
    char *kind;     /* 'c' or 'd' per input */
    double *time;   /* rows */
    double *values; /* rows x n */
} Table;

/* The inputs at time t, as fmusim gives them (the top of this file). */
static void table_at(const Table *table, double t, double *in) {
    int r = 0, j;
    while (r + 1 < table->rows && table->time[r + 1] <= t) r++;
    for (j = 0; j < table->n; j++) {
        double v = table->values[r * table->n + j];
        if (table->kind[j] == 'c' && r + 1 < table->rows) {
            double next = table->values[(r + 1) * table->n + j];
            v += (t - table->time[r]) * (next - v) / (table->time[r + 1] - table->time[r]);
        }
        in[j] = v;
    }
}

static int read_value(FILE *scenario, double *value) {
    char token[64];
    if (fscanf(scenario, "%63s", token) != 1) return 0;
    *value = strtod(token, NULL); /* strtod reads "nan" */
    return 1;
}

int main(int argc, char **argv) {
    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    void *library;
    FILE *scenario;
    fmi2Component c;
    double dt, value;
    int n_steps, k, j, n_par, n_in, n_out;
    fmi2ValueReference *in_vr, *out_vr, vr;
    double *in, *out;
    char type, word[16];
    SetReal set_real;
    DoStep do_step;
    GetReal get_real;
    struct timespec started, ended;
    int one_by_one = argc == 6 && !strcmp(argv[5], "one-by-one");
    Table table = {0, 0, NULL, NULL, NULL};
    if (argc != 5 && !one_by_one) {
        fprintf(stderr, "usage: host LIBRARY RESOURCES_URI GUID SCENARIO [one-by-one]\n");
        return 2;
    }
    library = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!library) {
        fprintf(stderr, "dlopen: %s\n", dlerror());
        return 1;
    }
    scenario = fopen(argv[4], "r");
    if (!scenario || fscanf(scenario, "%lf %d parameters %d", &dt, &n_steps, &n_par) != 3) return 2;
    c = ((Instantiate)symbol(library, "fmi2Instantiate"))("host", fmi2CoSimulation, argv[3], argv[2], &callbacks,
                                                          fmi2False, fmi2False);
    if (!c) {
        fprintf(stderr, "fmi2Instantiate failed\n");
        return 1;
    }
    CHECK(((Setup)symbol(library, "fmi2SetupExperiment"))(c, fmi2False, 0.0, 0.0, fmi2False, 0.0));
    CHECK(((Call)symbol(library, "fmi2EnterInitializationMode"))(c));
    for (k = 0; k < n_par; k++) {
        if (fscanf(scenario, "%u %c %lf", &vr, &type, &value) != 3) return 2;
        if (type == 'B') {
            fmi2Boolean b = value != 0.0;
            CHECK(((SetBoolean)symbol(library, "fmi2SetBoolean"))(c, &vr, 1, &b));
        } else {
            CHECK(((SetReal)symbol(library, "fmi2SetReal"))(c, &vr, 1, &value));
        }
    }
    if (fscanf(scenario, " %15s %d", word, &n_in) != 2) return 2;
    if (!strcmp(word, "table") && fscanf(scenario, "%d", &table.rows) != 1) return 2;
    in_vr = malloc(sizeof *in_vr * (n_in + 1));
    in = malloc(sizeof *in * (n_in + 1));
    table.n = n_in;
    table.kind = malloc((size_t)n_in + 1);
    for (k = 0; k < n_in; k++) {
        if (fscanf(scenario, "%u", &in_vr[k]) != 1) return 2;
        if (table.rows && fscanf(scenario, " %c", &table.kind[k]) != 1) return 2;
    }
    if (fscanf(scenario, " outputs %d", &n_out) != 1) return 2;
    out_vr = malloc(sizeof *out_vr * (n_out + 1));
    out = malloc(sizeof *out * (n_out + 1));
    for (k = 0; k < n_out; k++)
        if (fscanf(scenario, "%u", &out_vr[k]) != 1) return 2;
    if (table.rows) { /* the whole input file, applied at t = 0 during initialisation too */
        table.time = malloc(sizeof *table.time * table.rows);
        table.values = malloc(sizeof *table.values * table.rows * (n_in + 1));
        for (k = 0; k < table.rows; k++) {
            if (!read_value(scenario, &table.time[k])) return 2;
            for (j = 0; j < n_in; j++)
                if (!read_value(scenario, &table.values[k * n_in + j])) return 2;
        }
        table_at(&table, 0.0, in);
        CHECK(((SetReal)symbol(library, "fmi2SetReal"))(c, in_vr, n_in, in));
    }
    CHECK(((Call)symbol(library, "fmi2ExitInitializationMode"))(c));
    set_real = (SetReal)symbol(library, "fmi2SetReal"); /* looked up once: the loop times the FMU */
    do_step = (DoStep)symbol(library, "fmi2DoStep");
    get_real = (GetReal)symbol(library, "fmi2GetReal");
    clock_gettime(CLOCK_MONOTONIC, &started);
    for (k = 0; k < n_steps; k++) {
        if (table.rows) {
            table_at(&table, k * dt, in);
        } else {
            for (j = 0; j < n_in; j++)
                if (!read_value(scenario, &in[j])) return 2;
        }
        CHECK(set_real(c, in_vr, n_in, in));
        CHECK(do_step(c, k * dt, dt, fmi2True));
        if (one_by_one) {
            for (j = 0; j < n_out; j++) CHECK(get_real(c, &out_vr[j], 1, &out[j]));
        } else {
            CHECK(get_real(c, out_vr, n_out, out));
        }
        for (j = 0; j < n_out; j++) printf(j ? " %.17g" : "%.17g", out[j]);
        printf("\n");
    }
    clock_gettime(CLOCK_MONOTONIC, &ended);
    CHECK(((Call)symbol(library, "fmi2Terminate"))(c));
    ((Free)symbol(library, "fmi2FreeInstance"))(c);
    dlclose(library);
    free(in_vr); free(in); free(out_vr); free(out);
    free(table.kind); free(table.time); free(table.values);
    fclose(scenario);
    fprintf(stderr, "stepping %.6f s\n", (double)(ended.tv_sec - started.tv_sec) + 1e-9 * (ended.tv_nsec - started.tv_nsec));
    return 0;
}
