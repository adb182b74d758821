/* A minimal FMI 2.0 co-simulation host in C, with no Python in its process (tests only).

   host LIBRARY RESOURCES_URI GUID SCENARIO

   SCENARIO (text): "dt n_steps", then "parameters K" and K lines "vr R|B value" set during
   initialisation, then "inputs M vr..." and "outputs P vr...", then n_steps rows of M input
   values ("nan" for a missing one). Prints one row of P outputs (%.17g) after each step.
   Exits 1 on any status other than fmi2OK, naming the call. */
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

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

int main(int argc, char **argv) {
    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    void *library;
    FILE *scenario;
    fmi2Component c;
    double dt, value;
    int n_steps, k, j, n_par, n_in, n_out;
    fmi2ValueReference *in_vr, *out_vr, vr;
    double *in, *out;
    char type;
    if (argc != 5) {
        fprintf(stderr, "usage: host LIBRARY RESOURCES_URI GUID SCENARIO\n");
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
    CHECK(((Call)symbol(library, "fmi2ExitInitializationMode"))(c));
    if (fscanf(scenario, " inputs %d", &n_in) != 1) return 2;
    in_vr = malloc(sizeof *in_vr * (n_in + 1));
    in = malloc(sizeof *in * (n_in + 1));
    for (k = 0; k < n_in; k++)
        if (fscanf(scenario, "%u", &in_vr[k]) != 1) return 2;
    if (fscanf(scenario, " outputs %d", &n_out) != 1) return 2;
    out_vr = malloc(sizeof *out_vr * (n_out + 1));
    out = malloc(sizeof *out * (n_out + 1));
    for (k = 0; k < n_out; k++)
        if (fscanf(scenario, "%u", &out_vr[k]) != 1) return 2;
    for (k = 0; k < n_steps; k++) {
        for (j = 0; j < n_in; j++) {
            char token[64];
            if (fscanf(scenario, "%63s", token) != 1) return 2;
            in[j] = strtod(token, NULL); /* strtod reads "nan" */
        }
        CHECK(((SetReal)symbol(library, "fmi2SetReal"))(c, in_vr, n_in, in));
        CHECK(((DoStep)symbol(library, "fmi2DoStep"))(c, k * dt, dt, fmi2True));
        CHECK(((GetReal)symbol(library, "fmi2GetReal"))(c, out_vr, n_out, out));
        for (j = 0; j < n_out; j++) printf(j ? " %.17g" : "%.17g", out[j]);
        printf("\n");
    }
    CHECK(((Call)symbol(library, "fmi2Terminate"))(c));
    ((Free)symbol(library, "fmi2FreeInstance"))(c);
    dlclose(library);
    free(in_vr); free(in); free(out_vr); free(out);
    fclose(scenario);
    return 0;
}
