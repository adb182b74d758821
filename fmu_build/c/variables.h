/* The FMU's variables, their value references and which calls may change them: the C twin of
   fmu_build/variables.py, shared by the standalone FMU (nodeforce_fmu.c) and the guard in front
   of the Python FMU (guard.c), so both refuse exactly the same calls.

   Every value lives in one array indexed by value reference, in this order:
       force[1..N]      Boolean parameter, fixed
       T_start          Real parameter, fixed
       <inputs>         Real inputs (n_in)
       T_forced[1..N]   Real inputs
       T[1..N]          Real outputs
       <effect>.<name>  Real parameters, fixed (n_par) */
#ifndef NODEFORCE_VARIABLES_H
#define NODEFORCE_VARIABLES_H

#include <stdio.h>
#include <stdlib.h>

#include "fmi2.h"

/* The slave's state, as FMI 2.0 section 4.2.4 (table 2) decides what a call may do. */
enum { INSTANTIATED, INITIALISATION, STEPPING, TERMINATED };

typedef struct {
    int n, n_in, n_par; /* nodes, inputs before T_forced, effect parameters */
} Layout;

static inline int vr_force(const Layout *l) { (void)l; return 0; }
static inline int vr_T_start(const Layout *l) { return l->n; }
static inline int vr_inputs(const Layout *l) { return l->n + 1; }
static inline int vr_T_forced(const Layout *l) { return vr_inputs(l) + l->n_in; }
static inline int vr_T(const Layout *l) { return vr_T_forced(l) + l->n; }
static inline int vr_parameters(const Layout *l) { return vr_T(l) + l->n; }
static inline int layout_size(const Layout *l) { return vr_parameters(l) + l->n_par; }

/* The three counts "N N_IN N_PAR" of a layout; 0 if the text is not that (strtol, not
   sscanf, whose C99 name needs GLIBC_2.7: see glibc.h). */
static inline int read_sizes(const char *text, Layout *l) {
    int *counts[3] = {&l->n, &l->n_in, &l->n_par}, k;
    char *end;
    for (k = 0; k < 3; k++) {
        long value = strtol(text, &end, 10);
        if (end == text || value < 0 || value > 100000000L) return 0;
        *counts[k] = (int)value;
        text = end;
    }
    return 1;
}

/* Why the standard forbids this get or set of a Real (real) or Boolean (!real), written into
   reason; 0 when every reference may be read (or, setting, written) in this state. */
static inline int refusal(const Layout *l, const fmi2ValueReference vr[], size_t nvr, int real, int setting, int state,
                   char *reason, size_t size) {
    size_t k;
    for (k = 0; k < nvr; k++) {
        int r = (int)vr[k];
        int boolean = r < l->n;
        int fixed = r <= vr_T_start(l) || r >= vr_parameters(l);
        if (vr[k] >= (fmi2ValueReference)layout_size(l)) {
            snprintf(reason, size, "value reference %u does not exist (0..%d)", vr[k], layout_size(l) - 1);
            return 1;
        }
        if (boolean == real) {
            snprintf(reason, size, "value reference %d is %s, not %s", r, real ? "Boolean" : "Real",
                     real ? "Real" : "Boolean");
            return 1;
        }
        if (!setting) continue;
        if (r >= vr_T(l) && r < vr_parameters(l)) {
            snprintf(reason, size, "value reference %d is an output, which cannot be set", r);
            return 1;
        }
        if (fixed && state != INSTANTIATED && state != INITIALISATION) {
            snprintf(reason, size, "value reference %d is a fixed parameter, which cannot change after initialisation",
                     r);
            return 1;
        }
        if (state == TERMINATED) {
            snprintf(reason, size, "the slave is terminated");
            return 1;
        }
    }
    return 0;
}

/* Why the standard forbids this doStep, written into reason; 0 when it may step. */
static inline int step_refusal(int state, double step_size, char *reason, size_t size) {
    if (state != STEPPING) {
        snprintf(reason, size, "fmi2DoStep before initialisation ended, or after fmi2Terminate");
        return 1;
    }
    if (!(step_size > 0.0)) {
        snprintf(reason, size, "fmi2DoStep with communicationStepSize %g s: it must be > 0", step_size);
        return 1;
    }
    return 0;
}

/* Why a get or set of a type this FMU does not have (Integer, String) is refused; 0 for none. */
static inline int no_such_type(const char *type, size_t nvr, char *reason, size_t size) {
    if (nvr == 0) return 0;
    snprintf(reason, size, "this FMU has no %s variables", type);
    return 1;
}

#endif
