/* The master's loop over the steps of a run (cosim/fmi.py, `FmuInstance.run`): before each step
   set the inputs and their slopes, step, get the outputs, through the FMU's own FMI functions,
   the addresses FMPy bound from its library. The same calls, in the same order and with the same
   values, as the loop in Python it stands for; only the interpreter's work between them is gone
   (some 10 us a step, most of a small building's step).

   A transfer is one set or get a step: the value references it names, the buffer of every value
   of their variables (FMI 3.0 sets whole arrays: the elements no column gives keep their start
   values), and where column j of a row goes in that buffer. */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct {
    const uint32_t *refs;
    size_t n_refs;
    double *values;
    size_t n_values;
    const int64_t *positions;
    int64_t n;
} Transfer;

enum { SET_REAL2 = 0, SET_DERIVATIVES2 = 1, SET_FLOAT3 = 2 };  /* how a transfer is set */

typedef int (*SetReal2)(void *, const uint32_t *, size_t, const double *);
typedef int (*SetDerivatives2)(void *, const uint32_t *, size_t, const int *, const double *);
typedef int (*Float3)(void *, const uint32_t *, size_t, double *, size_t);  /* set and get alike */
typedef int (*DoStep2)(void *, double, double, int);
typedef int (*DoStep3)(void *, double, double, bool, bool *, bool *, bool *, double *);
typedef int (*GetReal2)(void *, const uint32_t *, size_t, double *);

#define ERROR 2  /* a status above fmiWarning (1 in FMI 2.0 and 3.0 alike) stops the run */

static int set(int form, void *function, void *instance, const Transfer *t, const double *row, int *orders) {
    for (int64_t j = 0; j < t->n; j++)
        t->values[t->positions[j]] = row[j];
    switch (form) {
    case SET_REAL2: return ((SetReal2)function)(instance, t->refs, t->n_refs, t->values);
    case SET_DERIVATIVES2: return ((SetDerivatives2)function)(instance, t->refs, t->n_refs, orders, t->values);
    default: return ((Float3)function)(instance, t->refs, t->n_refs, t->values, t->n_values);
    }
}

/* Steps k = 0 .. n_steps-1 from times[k] by steps[k]; row k of `inputs` (inputs->n columns) and
   of `slopes` (slopes->n) before step k, the outputs after it into row k - skip of `outputs`
   (outputs->n columns) for k >= skip. `version` 2 or 3; `input_form` and `slope_form` as above.
   Returns -1, or 4 k + c where call c of step k (0 inputs, 1 slopes, 2 doStep, 3 outputs)
   returned `*status` above warning. */
__attribute__((visibility("default")))
int64_t nodeforce_master_steps(int version, void *instance, void *set_inputs, int input_form, void *set_slopes,
                               int slope_form, void *do_step, void *get_outputs, const Transfer *in,
                               const Transfer *slope, const Transfer *out, int64_t n_steps,
                               const double *times, const double *steps, const double *inputs,
                               const double *slopes, double *outputs, int64_t skip, int *orders, int *status) {
    bool event, terminate, early;
    double last;
    for (int64_t k = 0; k < n_steps; k++) {
        if (in->n && (*status = set(input_form, set_inputs, instance, in, inputs + k * in->n, orders)) >= ERROR)
            return 4 * k;
        if (slope->n && (*status = set(slope_form, set_slopes, instance, slope, slopes + k * slope->n, orders)) >= ERROR)
            return 4 * k + 1;
        *status = version == 2 ? ((DoStep2)do_step)(instance, times[k], steps[k], 1)
                               : ((DoStep3)do_step)(instance, times[k], steps[k], true, &event, &terminate, &early, &last);
        if (*status >= ERROR)
            return 4 * k + 2;
        if (k < skip)
            continue;
        *status = version == 2 ? ((GetReal2)get_outputs)(instance, out->refs, out->n_refs, out->values)
                               : ((Float3)get_outputs)(instance, out->refs, out->n_refs, out->values, out->n_values);
        if (*status >= ERROR)
            return 4 * k + 3;
        double *row = outputs + (k - skip) * out->n;
        for (int64_t j = 0; j < out->n; j++)
            row[j] = out->values[out->positions[j]];
    }
    return -1;
}
