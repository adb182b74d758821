/* The FMU's variables, their value references and which calls may change them: the C twin of
   fmu_build/variables.py, shared by the standalone FMU (nodeforce_fmu.c) and the guard in front
   of the Python FMU (guard.c), so both refuse exactly the same calls.

   Every value lives in one array indexed by value reference, in this order:
       force[1..N]      Boolean parameter, fixed
       T_start[1..N]    Real parameters, fixed: the state at the start
       <inputs>         Real inputs (n_in)
       T_forced[1..N]   Real inputs
       T[1..N]          Real outputs
       <parameters>     Real parameters, fixed (n_par): the building's properties, an effect's
       max_step         Real parameter, tunable (s): the longest internal step of a doStep
   The names of the inputs and parameters, one a line, are resources/names.txt. A Real set must
   be finite, but T_forced's NaN ("not measured"). */
#ifndef NODEFORCE_VARIABLES_H
#define NODEFORCE_VARIABLES_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2.h"

/* The slave's state, as FMI 2.0 section 4.2.4 (table 2) decides what a call may do. */
enum { INSTANTIATED, INITIALISATION, STEPPING, TERMINATED };

typedef struct {
    int n, n_in, n_par; /* nodes, inputs before T_forced, other parameters */
    char **names;       /* n_in + n_par: the inputs' and parameters' names (NULL: not read) */
} Layout;

static inline int vr_force(const Layout *l) { (void)l; return 0; }
static inline int vr_T_start(const Layout *l) { return l->n; }
static inline int vr_inputs(const Layout *l) { return 2 * l->n; }
static inline int vr_T_forced(const Layout *l) { return vr_inputs(l) + l->n_in; }
static inline int vr_T(const Layout *l) { return vr_T_forced(l) + l->n; }
static inline int vr_parameters(const Layout *l) { return vr_T(l) + l->n; }
static inline int vr_max_step(const Layout *l) { return vr_parameters(l) + l->n_par; }
static inline int layout_size(const Layout *l) { return vr_max_step(l) + 1; }

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

/* The names of resources/names.txt (path) into l->names; 0 if it cannot be read. */
static inline int read_names(Layout *l, const char *path) {
    char line[4096];
    int k, count = l->n_in + l->n_par;
    FILE *f = path ? fopen(path, "r") : NULL;
    if (!f) return 0;
    l->names = calloc((size_t)count + 1, sizeof(char *));
    for (k = 0; l->names && k < count && fgets(line, sizeof line, f); k++) {
        size_t length = strcspn(line, "\r\n");
        if (!(l->names[k] = malloc(length + 1))) break;
        memcpy(l->names[k], line, length);
        l->names[k][length] = 0;
    }
    fclose(f);
    return l->names && k == count;
}

static inline void free_names(Layout *l) {
    int k;
    for (k = 0; l->names && k < l->n_in + l->n_par; k++) free(l->names[k]);
    free(l->names);
    l->names = NULL;
}

/* The name of an FMI 2.0 value reference, in `name`. */
static inline void variable_name(const Layout *l, int r, char *name, size_t size) {
    const char *named = NULL;
    if (r >= vr_inputs(l) && r < vr_T_forced(l)) named = l->names ? l->names[r - vr_inputs(l)] : "an input";
    else if (r == vr_max_step(l)) named = "max_step";
    else if (r >= vr_parameters(l)) named = l->names ? l->names[l->n_in + r - vr_parameters(l)] : "a parameter";
    if (named) snprintf(name, size, "%s", named);
    else if (r < vr_T_start(l)) snprintf(name, size, "force[%d]", r + 1);
    else if (r < vr_inputs(l)) snprintf(name, size, "T_start[%d]", r - vr_T_start(l) + 1);
    else if (r < vr_T(l)) snprintf(name, size, "T_forced[%d]", r - vr_T_forced(l) + 1);
    else snprintf(name, size, "T[%d]", r - vr_T(l) + 1);
}

/* Whether the standard forbids this get or set of Reals (real) or Booleans (!real) in this
   state, or refuses a value set (a Real not finite, but T_forced's NaN; values: the Reals set,
   or NULL): -1 when every reference may be read (or written); else the position k of the first
   refused, and in `reason` why, said of the variable (the caller names it: "value reference
   <vr> (<name>) " + reason). time : the communication point, for the message. */
static inline long refusal(const Layout *l, const fmi2ValueReference vr[], size_t nvr, const double *values, int real,
                           int setting, int state, double time, char *reason, size_t size) {
    size_t k;
    for (k = 0; k < nvr; k++) {
        int r = (int)vr[k];
        int boolean = r < l->n;
        int fixed = r < vr_inputs(l) || (r >= vr_parameters(l) && r < vr_max_step(l));
        if (vr[k] >= (fmi2ValueReference)layout_size(l)) {
            snprintf(reason, size, "does not exist (0..%d)", layout_size(l) - 1);
            return (long)k;
        }
        if (boolean == real) {
            snprintf(reason, size, "is %s, not %s", real ? "Boolean" : "Real", real ? "Real" : "Boolean");
            return (long)k;
        }
        if (!setting) continue;
        if (r >= vr_T(l) && r < vr_parameters(l)) {
            snprintf(reason, size, "is an output, which cannot be set");
            return (long)k;
        }
        if (fixed && state != INSTANTIATED && state != INITIALISATION) {
            snprintf(reason, size, "is a fixed parameter, which cannot change after initialisation");
            return (long)k;
        }
        if (state == TERMINATED) {
            snprintf(reason, size, "cannot be set: the slave is terminated");
            return (long)k;
        }
        if (values && values[k] - values[k] != 0.0 && !(r >= vr_T_forced(l) && r < vr_T(l))) {
            snprintf(reason, size, "set to %g at t = %.17g s: it must be finite (NaN means \"not measured\" "
                     "on T_forced only)", values[k], time);
            return (long)k;
        }
    }
    return -1;
}

/* refusal's full message for an FMI 2.0 call, into `message`; 0 when nothing is refused. */
static inline int refused2(const Layout *l, const fmi2ValueReference vr[], size_t nvr, const double *values, int real,
                           int setting, int state, double time, char *message, size_t size) {
    char reason[256], name[128];
    long k = refusal(l, vr, nvr, values, real, setting, state, time, reason, sizeof reason);
    if (k < 0) return 0;
    if ((int)vr[k] < layout_size(l)) variable_name(l, (int)vr[k], name, sizeof name);
    else snprintf(name, sizeof name, "none");
    snprintf(message, size, "value reference %u (%s) %s", vr[k], name, reason);
    return 1;
}

/* Why fmi2SetRealInputDerivatives is refused, in `message` (0 when it is not): only the first
   derivative (order 1) of an input or of T_forced, finite, when the inputs may be set. */
static inline int derivative_refusal(const Layout *l, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer order[],
                                     const double value[], int state, double time, char *message, size_t size) {
    size_t k;
    char name[128];
    for (k = 0; k < nvr; k++) {
        if (refused2(l, vr + k, 1, NULL, 1, 1, state, time, message, size)) return 1;
        if ((int)vr[k] < vr_inputs(l) || (int)vr[k] >= vr_T(l)) {
            variable_name(l, (int)vr[k], name, sizeof name);
            snprintf(message, size, "value reference %u (%s) is not an input: it has no input derivative", vr[k], name);
            return 1;
        }
        if (order[k] != 1 || value[k] - value[k] != 0.0) {
            variable_name(l, (int)vr[k], name, sizeof name);
            snprintf(message, size, "value reference %u (%s): derivative of order %d set to %g at t = %.17g s: only a "
                     "finite first derivative is used", vr[k], name, (int)order[k], value[k], time);
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
