/* The FMI 3.0 co-simulation interface of both FMUs, over their FMI 2.0 one: compiled into one
   library with nodeforce_fmu.c (the standalone FMU) or with guard.c (the Python FMU, in front
   of pythonfmu's FMI 2.0 binary), it calls that library's fmi2* functions (bound inside the
   library, -Wl,-Bsymbolic). The model, its checks and its numbers are the FMI 2.0 FMU's; this
   file only renames the variables, translates the calls and keeps the time.

   Variables (FMI 3.0 value references), over the FMI 2.0 layout of variables.h:
       0                 time            independent
       1                 force[N]        Boolean parameter, fixed      FMI 2.0: force[1..N]
       2                 T_start[N]      Float64 parameter, fixed      FMI 2.0: T_start[1..N]
       3 .. 2+N_IN       the inputs      Float64 inputs
       3+N_IN            T_forced[N]     Float64 input, discrete       FMI 2.0: T_forced[1..N]
       4+N_IN            T[N]            Float64 output                FMI 2.0: T[1..N]
       5+N_IN ..         the other parameters (properties, an effect's), Float64, fixed
       5+N_IN+N_PAR      max_step        Float64 parameter, tunable    FMI 2.0: max_step
       6+N_IN+N_PAR ..   der(<input>)    Float64 inputs, derivative of each input
       6+2N_IN+N_PAR     der(T_forced)[N] Float64 input, discrete, derivative of T_forced
   FMI 3.0 has no fmi2SetRealInputDerivatives: the inputs' first derivatives are inputs of their
   own, declared with the `derivative` attribute, which this file hands to the FMI 2.0 instance's
   fmi2SetRealInputDerivatives (they hold for the next step, as there).
   The sizes come from resources/fmi3.txt ("nodeforce-fmi3/1", then "sizes N N_IN N_PAR"), the
   names from resources/names.txt. A get or set is checked here, by the FMI 2.0 rules of
   variables.h, so that a refusal names the FMI 3.0 value reference. No event mode, no
   intermediate update: the functions of those (and of model exchange and scheduled execution)
   answer fmi3Error, with the reason logged. */
#define _GNU_SOURCE
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2.h"
#include "fmi3.h"
#include "glibc.h"
#include "variables.h"

FMI2_EXPORT fmi2InstantiateTYPE fmi2Instantiate;
FMI2_EXPORT fmi2FreeInstanceTYPE fmi2FreeInstance;
FMI2_EXPORT fmi2SetDebugLoggingTYPE fmi2SetDebugLogging;
FMI2_EXPORT fmi2SetupExperimentTYPE fmi2SetupExperiment;
FMI2_EXPORT fmi2EnterInitializationModeTYPE fmi2EnterInitializationMode;
FMI2_EXPORT fmi2ExitInitializationModeTYPE fmi2ExitInitializationMode;
FMI2_EXPORT fmi2TerminateTYPE fmi2Terminate;
FMI2_EXPORT fmi2ResetTYPE fmi2Reset;
FMI2_EXPORT fmi2GetRealTYPE fmi2GetReal;
FMI2_EXPORT fmi2SetRealTYPE fmi2SetReal;
FMI2_EXPORT fmi2GetBooleanTYPE fmi2GetBoolean;
FMI2_EXPORT fmi2SetBooleanTYPE fmi2SetBoolean;
FMI2_EXPORT fmi2GetFMUstateTYPE fmi2GetFMUstate;
FMI2_EXPORT fmi2SetFMUstateTYPE fmi2SetFMUstate;
FMI2_EXPORT fmi2FreeFMUstateTYPE fmi2FreeFMUstate;
FMI2_EXPORT fmi2SerializedFMUstateSizeTYPE fmi2SerializedFMUstateSize;
FMI2_EXPORT fmi2SerializeFMUstateTYPE fmi2SerializeFMUstate;
FMI2_EXPORT fmi2DeSerializeFMUstateTYPE fmi2DeSerializeFMUstate;
FMI2_EXPORT fmi2DoStepTYPE fmi2DoStep;
FMI2_EXPORT fmi2SetRealInputDerivativesTYPE fmi2SetRealInputDerivatives;

typedef struct {
    fmi2Component inner; /* the FMI 2.0 instance */
    Layout layout;
    int state; /* variables.h's, as the FMI 2.0 instance's */
    double time;
    char *name;
    fmi3InstanceEnvironment environment;
    fmi3LogMessageCallback log;
    fmi2CallbackFunctions callbacks; /* the FMI 2.0 instance's, which log through `log` */
    double *derivatives;             /* N_IN + N: der(<input>), der(T_forced) as set for the next step */
} Adapter;

/* An FMU state: the state and time beside the FMI 2.0 state. */
typedef struct {
    int state;
    double time;
    fmi2FMUstate inner;
} AdapterState;

static fmi3Status refuse(Adapter *a, const char *format, ...) {
    char message[512];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    if (a && a->log) a->log(a->environment, fmi3Error, "logStatusError", message);
    return fmi3Error;
}

/* The FMI 2.0 instance's logger: its message, formatted, to the FMI 3.0 callback. */
static void forward_log(fmi2ComponentEnvironment environment, fmi2String name, fmi2Status status,
                        fmi2String category, fmi2String message, ...) {
    Adapter *a = environment;
    char text[8192];
    va_list args;
    (void)name;
    va_start(args, message);
    vsnprintf(text, sizeof text, message, args);
    va_end(args);
    if (a->log) a->log(a->environment, (fmi3Status)(status > fmi2Fatal ? fmi2Fatal : status), category, text);
}

/* ------------------------------------------------------------------ variables */
enum { NONE, TIME, REAL, BOOLEAN };

/* What an FMI 3.0 value reference is, and its FMI 2.0 value references first .. first+count-1. */
static int variable(const Layout *l, fmi3ValueReference vr, int *first, int *count) {
    long r = (long)vr, inputs = 3, T_forced = inputs + l->n_in, parameters = T_forced + 2;
    *count = 1;
    if (r == 0) return TIME;
    if (r == 1) {
        *first = vr_force(l);
        *count = l->n;
        return BOOLEAN;
    }
    if (r == 2) {
        *first = vr_T_start(l);
        *count = l->n;
    } else if (r < T_forced) *first = vr_inputs(l) + (int)(r - inputs);
    else if (r == T_forced || r == T_forced + 1) {
        *first = r == T_forced ? vr_T_forced(l) : vr_T(l);
        *count = l->n;
    } else if (r <= parameters + l->n_par) *first = vr_parameters(l) + (int)(r - parameters); /* max_step last */
    else return NONE;
    return REAL;
}

/* Whether an FMI 3.0 value reference is a derivative input, and the FMI 2.0 value references
   of the inputs it is the derivative of: first .. first+count-1. */
static int is_derivative(const Layout *l, fmi3ValueReference vr, int *first, int *count) {
    long r = (long)vr, base = 6 + l->n_in + l->n_par;
    if (r < base || r > base + l->n_in) return 0;
    *first = r < base + l->n_in ? vr_inputs(l) + (int)(r - base) : vr_T_forced(l);
    *count = r < base + l->n_in ? 1 : l->n;
    return 1;
}

/* The FMI 2.0 value references of an FMI 3.0 list of one type (time aside): malloc'ed, their
   number in *n; NULL with the reason logged if a reference is not of that type or the number
   of values is not nValues. */
static fmi2ValueReference *expand(Adapter *a, const fmi3ValueReference vr[], size_t nvr, int type, size_t nValues,
                                  size_t *n) {
    size_t k, total = 0;
    int first, count, j, kind;
    fmi2ValueReference *refs;
    for (k = 0; k < nvr; k++) {
        kind = variable(&a->layout, vr[k], &first, &count);
        if (kind == NONE || (kind == TIME ? type != REAL : kind != type)) {
            refuse(a, "value reference %u is not a %s variable of this FMU", vr[k], type == REAL ? "Float64" : "Boolean");
            return NULL;
        }
        total += (size_t)count;
    }
    if (total != nValues) {
        refuse(a, "%zu values given for %zu", nValues, total);
        return NULL;
    }
    refs = malloc(sizeof *refs * (total + 1));
    if (!refs) {
        refuse(a, "out of memory");
        return NULL;
    }
    for (*n = 0, k = 0; k < nvr; k++) {
        if (variable(&a->layout, vr[k], &first, &count) == TIME) continue;
        for (j = 0; j < count; j++) refs[(*n)++] = (fmi2ValueReference)(first + j);
    }
    return refs;
}

/* Why the FMI 2.0 rules refuse this get or set of n references (expanded from vr; reals: the
   values set or NULL), said of the FMI 3.0 variable: 1 with the reason logged, else 0. */
static int refused3(Adapter *a, const fmi3ValueReference vr[], size_t nvr, const fmi2ValueReference refs[], size_t n,
                    const double *reals, int real, int setting) {
    char reason[256], name[128], element[32] = "";
    long at = refusal(&a->layout, refs, n, reals, real, setting, a->state, a->time, reason, sizeof reason);
    size_t k;
    int first, count;
    if (at < 0) return 0;
    for (k = 0; k < nvr; k++) { /* the FMI 3.0 variable and element of position `at` */
        if (variable(&a->layout, vr[k], &first, &count) == TIME) continue;
        if (at < count) break;
        at -= count;
    }
    variable_name(&a->layout, first + (int)at, name, sizeof name);
    if (count > 1) {
        snprintf(element, sizeof element, ", element %ld", at + 1);
        *strchr(name, '[') = 0; /* the array's name */
    }
    refuse(a, "value reference %u (%s%s) %s", vr[k], name, element, reason);
    return 1;
}

/* Values of the FMI 2.0 list (time aside) to or from the FMI 3.0 one, time at its places. */
static void place_time(Adapter *a, const fmi3ValueReference vr[], size_t nvr, const double *from, double *to,
                       int getting) {
    size_t k, at = 0, inner = 0;
    int first, count, j;
    for (k = 0; k < nvr; k++) {
        if (variable(&a->layout, vr[k], &first, &count) == TIME) {
            if (getting) to[at] = a->time;
            at++;
            continue;
        }
        for (j = 0; j < count; j++, at++, inner++) {
            if (getting) to[at] = from[inner];
            else to[inner] = from[at];
        }
    }
}

/* A get or set of Float64 (REAL) or Boolean values, through the FMI 2.0 instance: the values
   in FMI 2.0's order (time aside), fmi3Boolean (bool) as fmi2Boolean (int). */
static fmi3Status transfer(Adapter *a, const fmi3ValueReference vr[], size_t nvr, int type, size_t nValues,
                           void *values, int setting) {
    size_t n, k;
    fmi2ValueReference *refs;
    double *reals = NULL;
    fmi2Boolean *booleans = NULL;
    fmi3Status status;
    for (k = 0; setting && k < nvr; k++)
        if (vr[k] == 0) return refuse(a, "time (value reference 0) is the independent variable: it cannot be set");
    refs = expand(a, vr, nvr, type, nValues, &n);
    if (!refs) return fmi3Error;
    if (type == REAL) reals = malloc(sizeof *reals * (n + 1));
    else booleans = malloc(sizeof *booleans * (n + 1));
    if (!reals && !booleans) {
        free(refs);
        return refuse(a, "out of memory");
    }
    if (setting && reals) place_time(a, vr, nvr, values, reals, 0);
    for (k = 0; setting && booleans && k < n; k++) booleans[k] = ((fmi3Boolean *)values)[k] ? fmi2True : fmi2False;
    if (refused3(a, vr, nvr, refs, n, setting ? reals : NULL, type == REAL, setting)) status = fmi3Error;
    else if (reals) status = (fmi3Status)(setting ? fmi2SetReal(a->inner, refs, n, reals) : fmi2GetReal(a->inner, refs, n, reals));
    else status = (fmi3Status)(setting ? fmi2SetBoolean(a->inner, refs, n, booleans)
                                       : fmi2GetBoolean(a->inner, refs, n, booleans));
    if (!setting && status <= fmi3Warning) {
        if (reals) place_time(a, vr, nvr, reals, values, 1);
        for (k = 0; booleans && k < n; k++) ((fmi3Boolean *)values)[k] = booleans[k] != fmi2False;
    }
    free(reals);
    free(booleans);
    free(refs);
    return status;
}

/* A get or set of derivative inputs only: the FMI 2.0 instance checks and takes a set
   (fmi2SetRealInputDerivatives, order 1); a get answers what was set for the next step. */
static fmi3Status derivatives(Adapter *a, const fmi3ValueReference vr[], size_t nvr, size_t nValues, double *values,
                              int setting) {
    size_t k, at = 0, total = 0;
    int first, count, j;
    fmi2ValueReference *refs;
    fmi2Integer *orders;
    fmi3Status status;
    for (k = 0; k < nvr; k++) {
        is_derivative(&a->layout, vr[k], &first, &count);
        total += (size_t)count;
    }
    if (total != nValues) return refuse(a, "%zu values given for %zu", nValues, total);
    refs = malloc(sizeof *refs * (total + 1));
    orders = malloc(sizeof *orders * (total + 1));
    if (!refs || !orders) {
        free(refs);
        free(orders);
        return refuse(a, "out of memory");
    }
    for (k = 0; k < nvr; k++) {
        is_derivative(&a->layout, vr[k], &first, &count);
        for (j = 0; j < count; j++, at++) {
            refs[at] = (fmi2ValueReference)(first + j);
            orders[at] = 1;
        }
    }
    status = setting ? (fmi3Status)fmi2SetRealInputDerivatives(a->inner, refs, total, orders, values) : fmi3OK;
    for (k = 0; status <= fmi3Warning && k < total; k++) {
        double *kept = a->derivatives + refs[k] - vr_inputs(&a->layout);
        if (setting) *kept = values[k];
        else values[k] = *kept;
    }
    free(refs);
    free(orders);
    return status;
}

/* A Float64 get or set: runs of derivative inputs and of the other variables, in turn. */
static fmi3Status float64(Adapter *a, const fmi3ValueReference vr[], size_t nvr, size_t nValues, double *values,
                          int setting) {
    size_t k = 0, at = 0;
    fmi3Status status = fmi3OK, next;
    while (k < nvr) {
        size_t j = k, size = 0;
        int first, count, derivative = is_derivative(&a->layout, vr[k], &first, &count);
        for (; j < nvr; j++) {
            if (is_derivative(&a->layout, vr[j], &first, &count) != derivative) break;
            if (!derivative && variable(&a->layout, vr[j], &first, &count) == NONE) count = 1;
            size += (size_t)count;
        }
        if (j == nvr && k == 0) size = nValues; /* one run: transfer checks the count */
        if (at + size > nValues) return refuse(a, "%zu values given for more", nValues);
        next = derivative ? derivatives(a, vr + k, j - k, size, values + at, setting)
                          : transfer(a, vr + k, j - k, REAL, size, values + at, setting);
        if (next > status) status = next;
        if (status > fmi3Warning) return status;
        at += size;
        k = j;
    }
    if (at != nValues) return refuse(a, "%zu values given for %zu", nValues, at);
    return status;
}

FMI3_EXPORT fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                                      fmi3Float64 values[], size_t nValues) {
    return float64(instance, vr, nvr, nValues, values, 0);
}

FMI3_EXPORT fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                                      const fmi3Float64 values[], size_t nValues) {
    return float64(instance, vr, nvr, nValues, (double *)values, 1);
}

/* force[N] is the only Boolean. */
FMI3_EXPORT fmi3Status fmi3GetBoolean(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                                      fmi3Boolean values[], size_t nValues) {
    return transfer(instance, vr, nvr, BOOLEAN, nValues, values, 0);
}

FMI3_EXPORT fmi3Status fmi3SetBoolean(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr,
                                      const fmi3Boolean values[], size_t nValues) {
    return transfer(instance, vr, nvr, BOOLEAN, nValues, (void *)values, 1);
}

/* ------------------------------------------------------------------ instances */
/* A call that moves the instance to `state` when it succeeds. */
static fmi3Status moved(Adapter *a, fmi3Status status, int state) {
    if (status <= fmi3Warning) a->state = state;
    return status;
}

FMI3_EXPORT const char *fmi3GetVersion(void) { return "3.0"; }

FMI3_EXPORT fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                                           const fmi3String categories[]) {
    Adapter *a = instance;
    return (fmi3Status)fmi2SetDebugLogging(a->inner, loggingOn, nCategories, categories);
}

/* The layout from resources/fmi3.txt; 0 if it cannot be read. */
static int read_layout(const char *resources, Layout *l) {
    char *path = malloc(strlen(resources) + 16), header[32], sizes[64];
    FILE *f;
    int ok;
    if (!path) return 0;
    sprintf(path, "%s%sfmi3.txt", resources, resources[0] && resources[strlen(resources) - 1] == '/' ? "" : "/");
    f = fopen(path, "r");
    free(path);
    ok = f && fgets(header, sizeof header, f) && strcmp(header, "nodeforce-fmi3/1\n") == 0
         && fgets(sizes, sizeof sizes, f) && strncmp(sizes, "sizes ", 6) == 0 && read_sizes(sizes + 6, l);
    if (f) fclose(f);
    return ok;
}

FMI3_EXPORT fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                                     fmi3String resourcePath, fmi3Boolean visible,
                                                     fmi3Boolean loggingOn, fmi3Boolean eventModeUsed,
                                                     fmi3Boolean earlyReturnAllowed,
                                                     const fmi3ValueReference requiredIntermediateVariables[],
                                                     size_t nRequiredIntermediateVariables,
                                                     fmi3InstanceEnvironment instanceEnvironment,
                                                     fmi3LogMessageCallback logMessage,
                                                     fmi3IntermediateUpdateCallback intermediateUpdate) {
    Adapter *a = calloc(1, sizeof(Adapter));
    char *uri;
    (void)earlyReturnAllowed; (void)requiredIntermediateVariables; (void)nRequiredIntermediateVariables;
    (void)intermediateUpdate;
    if (!a) return NULL;
    a->environment = instanceEnvironment;
    a->log = logMessage;
    if (eventModeUsed) {
        refuse(a, "this FMU has no event mode (hasEventMode=\"false\")");
        free(a);
        return NULL;
    }
    if (!resourcePath || !read_layout(resourcePath, &a->layout)) {
        refuse(a, "cannot read %sfmi3.txt", resourcePath ? resourcePath : "the resources (no resourcePath)/");
        free(a);
        return NULL;
    }
    a->derivatives = calloc((size_t)(a->layout.n_in + a->layout.n) + 1, sizeof(double));
    uri = malloc(strlen(resourcePath) + 16);
    if (uri) {
        sprintf(uri, "%s%snames.txt", resourcePath,
                resourcePath[0] && resourcePath[strlen(resourcePath) - 1] == '/' ? "" : "/");
        if (!read_names(&a->layout, uri)) free_names(&a->layout); /* messages then say "an input" */
        free(uri);
    }
    a->state = INSTANTIATED;
    {   /* the FMI 2.0 instance logs to this one; its callbacks stay here, where it may keep them */
        const fmi2CallbackFunctions callbacks = {forward_log, calloc, free, NULL, a};
        memcpy(&a->callbacks, &callbacks, sizeof callbacks);
    }
    uri = malloc(strlen(resourcePath) + 8);
    a->name = malloc(strlen(instanceName ? instanceName : "") + 1);
    if (uri && a->name) {
        strcpy(a->name, instanceName ? instanceName : "");
        sprintf(uri, "file://%s", resourcePath);
        a->inner = fmi2Instantiate(a->name, fmi2CoSimulation, instantiationToken, uri, &a->callbacks,
                                   visible ? fmi2True : fmi2False, loggingOn ? fmi2True : fmi2False);
    }
    free(uri);
    if (!a->inner || !a->derivatives) {
        if (a->inner) fmi2FreeInstance(a->inner);
        free_names(&a->layout);
        free(a->name);
        free(a->derivatives);
        free(a);
        return NULL;
    }
    return a;
}

FMI3_EXPORT void fmi3FreeInstance(fmi3Instance instance) {
    Adapter *a = instance;
    if (!a) return;
    fmi2FreeInstance(a->inner);
    free_names(&a->layout);
    free(a->name);
    free(a->derivatives);
    free(a);
}

FMI3_EXPORT fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined,
                                                   fmi3Float64 tolerance, fmi3Float64 startTime,
                                                   fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    Adapter *a = instance;
    fmi3Status status = (fmi3Status)fmi2SetupExperiment(a->inner, toleranceDefined, tolerance, startTime,
                                                        stopTimeDefined, stopTime);
    if (status > fmi3Warning) return status;
    a->time = startTime;
    return moved(a, (fmi3Status)fmi2EnterInitializationMode(a->inner), INITIALISATION);
}

FMI3_EXPORT fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    Adapter *a = instance;
    return moved(a, (fmi3Status)fmi2ExitInitializationMode(a->inner), STEPPING);
}

FMI3_EXPORT fmi3Status fmi3Terminate(fmi3Instance instance) {
    Adapter *a = instance;
    return moved(a, (fmi3Status)fmi2Terminate(a->inner), TERMINATED);
}

FMI3_EXPORT fmi3Status fmi3Reset(fmi3Instance instance) {
    Adapter *a = instance;
    fmi3Status status = moved(a, (fmi3Status)fmi2Reset(a->inner), INSTANTIATED);
    if (status <= fmi3Warning) a->time = 0.0;
    memset(a->derivatives, 0, sizeof(double) * (size_t)(a->layout.n_in + a->layout.n));
    return status;
}

FMI3_EXPORT fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint,
                                  fmi3Float64 communicationStepSize, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                  fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation,
                                  fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime) {
    Adapter *a = instance;
    fmi3Status status = (fmi3Status)fmi2DoStep(a->inner, currentCommunicationPoint, communicationStepSize,
                                               noSetFMUStatePriorToCurrentPoint ? fmi2True : fmi2False);
    if (status <= fmi3Warning) a->time = currentCommunicationPoint + communicationStepSize;
    /* as the FMI 2.0 instance's, the derivatives held for that step only */
    memset(a->derivatives, 0, sizeof(double) * (size_t)(a->layout.n_in + a->layout.n));
    *eventHandlingNeeded = false;
    *terminateSimulation = false;
    *earlyReturn = false;
    *lastSuccessfulTime = status <= fmi3Warning ? a->time : currentCommunicationPoint;
    return status;
}

/* ------------------------------------------------------------------ FMU states */
FMI3_EXPORT fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *state) {
    Adapter *a = instance;
    AdapterState *s = *state ? *state : calloc(1, sizeof(AdapterState));
    fmi3Status status;
    if (!s) return refuse(a, "out of memory for a state");
    status = (fmi3Status)fmi2GetFMUstate(a->inner, &s->inner);
    if (status > fmi3Warning) {
        if (!*state) free(s);
        return status;
    }
    s->time = a->time;
    s->state = a->state;
    *state = s;
    return status;
}

FMI3_EXPORT fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState state) {
    Adapter *a = instance;
    AdapterState *s = state;
    fmi3Status status;
    if (!s) return refuse(a, "fmi3SetFMUState without a state");
    status = moved(a, (fmi3Status)fmi2SetFMUstate(a->inner, s->inner), s->state);
    if (status <= fmi3Warning) a->time = s->time;
    return status;
}

FMI3_EXPORT fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *state) {
    Adapter *a = instance;
    AdapterState *s = *state;
    fmi3Status status = fmi3OK;
    if (!s) return fmi3OK;
    if (s->inner) status = (fmi3Status)fmi2FreeFMUstate(a->inner, &s->inner);
    free(s);
    *state = NULL;
    return status;
}

/* A serialized state: the time's bytes and the state's (a double each), then the FMI 2.0 state's. */
#define HEAD (2 * sizeof(double))
FMI3_EXPORT fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState state, size_t *size) {
    Adapter *a = instance;
    fmi3Status status = (fmi3Status)fmi2SerializedFMUstateSize(a->inner, ((AdapterState *)state)->inner, size);
    if (status <= fmi3Warning) *size += HEAD;
    return status;
}

FMI3_EXPORT fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState state, fmi3Byte serializedState[],
                                             size_t size) {
    Adapter *a = instance;
    AdapterState *s = state;
    double head[2];
    if (size < HEAD) return refuse(a, "fmi3SerializeFMUState: no room for the state");
    head[0] = s->time;
    head[1] = s->state;
    memcpy(serializedState, head, HEAD);
    return (fmi3Status)fmi2SerializeFMUstate(a->inner, s->inner, (fmi2Byte *)serializedState + HEAD, size - HEAD);
}

FMI3_EXPORT fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[], size_t size,
                                               fmi3FMUState *state) {
    Adapter *a = instance;
    AdapterState *s;
    fmi3Status status;
    double head[2];
    if (size < HEAD) return refuse(a, "these bytes are not a serialized state of this FMU");
    memcpy(head, serializedState, HEAD);
    if (!(head[1] >= INSTANTIATED && head[1] <= TERMINATED))
        return refuse(a, "these bytes are not a serialized state of this FMU");
    s = calloc(1, sizeof(AdapterState));
    if (!s) return refuse(a, "out of memory for a state");
    s->time = head[0];
    s->state = (int)head[1];
    status = (fmi3Status)fmi2DeSerializeFMUstate(a->inner, (const fmi2Byte *)serializedState + HEAD, size - HEAD,
                                                 &s->inner);
    if (status > fmi3Warning) {
        free(s);
        return status;
    }
    *state = s;
    return status;
}

/* ------------------------------------------------------------------ what this FMU does not have */
#define NOT_SUPPORTED(function, ...)                                                          \
    FMI3_EXPORT fmi3Status function(fmi3Instance instance, __VA_ARGS__) {                     \
        return refuse(instance, "%s: not supported by this co-simulation FMU", #function);   \
    }
#define NOT_SUPPORTED_0(function)                                                             \
    FMI3_EXPORT fmi3Status function(fmi3Instance instance) {                                  \
        return refuse(instance, "%s: not supported by this co-simulation FMU", #function);   \
    }
/* Types of which this FMU has no variable: an empty list is fine, any reference is refused. */
#define NO_SUCH_TYPE(get, set, type)                                                                                  \
    FMI3_EXPORT fmi3Status get(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, type values[],     \
                               size_t nValues) {                                                                    \
        (void)vr; (void)values; (void)nValues;                                                                      \
        return nvr ? refuse(instance, "%s: this FMU has no such variables", #get) : fmi3OK;                         \
    }                                                                                                               \
    FMI3_EXPORT fmi3Status set(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, const type values[], \
                               size_t nValues) {                                                                    \
        (void)vr; (void)values; (void)nValues;                                                                      \
        return nvr ? refuse(instance, "%s: this FMU has no such variables", #set) : fmi3OK;                         \
    }
NO_SUCH_TYPE(fmi3GetFloat32, fmi3SetFloat32, fmi3Float32)
NO_SUCH_TYPE(fmi3GetInt8, fmi3SetInt8, fmi3Int8)
NO_SUCH_TYPE(fmi3GetUInt8, fmi3SetUInt8, fmi3UInt8)
NO_SUCH_TYPE(fmi3GetInt16, fmi3SetInt16, fmi3Int16)
NO_SUCH_TYPE(fmi3GetUInt16, fmi3SetUInt16, fmi3UInt16)
NO_SUCH_TYPE(fmi3GetInt32, fmi3SetInt32, fmi3Int32)
NO_SUCH_TYPE(fmi3GetUInt32, fmi3SetUInt32, fmi3UInt32)
NO_SUCH_TYPE(fmi3GetInt64, fmi3SetInt64, fmi3Int64)
NO_SUCH_TYPE(fmi3GetUInt64, fmi3SetUInt64, fmi3UInt64)
NO_SUCH_TYPE(fmi3GetString, fmi3SetString, fmi3String)
NOT_SUPPORTED(fmi3GetBinary, const fmi3ValueReference vr[], size_t nvr, size_t sizes[], fmi3Binary values[], size_t n)
NOT_SUPPORTED(fmi3SetBinary, const fmi3ValueReference vr[], size_t nvr, const size_t sizes[], const fmi3Binary values[],
              size_t n)
NOT_SUPPORTED(fmi3GetClock, const fmi3ValueReference vr[], size_t nvr, fmi3Clock values[])
NOT_SUPPORTED(fmi3SetClock, const fmi3ValueReference vr[], size_t nvr, const fmi3Clock values[])
NOT_SUPPORTED(fmi3GetNumberOfVariableDependencies, fmi3ValueReference vr, size_t *n)
NOT_SUPPORTED(fmi3GetVariableDependencies, fmi3ValueReference dependent, size_t elements[],
              fmi3ValueReference independents[], size_t independentElements[], fmi3DependencyKind kinds[], size_t n)
NOT_SUPPORTED(fmi3GetDirectionalDerivative, const fmi3ValueReference unknowns[], size_t nu,
              const fmi3ValueReference knowns[], size_t nk, const fmi3Float64 seed[], size_t ns,
              fmi3Float64 sensitivity[], size_t nse)
NOT_SUPPORTED(fmi3GetAdjointDerivative, const fmi3ValueReference unknowns[], size_t nu,
              const fmi3ValueReference knowns[], size_t nk, const fmi3Float64 seed[], size_t ns,
              fmi3Float64 sensitivity[], size_t nse)
NOT_SUPPORTED_0(fmi3EnterConfigurationMode)
NOT_SUPPORTED_0(fmi3ExitConfigurationMode)
NOT_SUPPORTED(fmi3GetIntervalDecimal, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 intervals[],
              fmi3IntervalQualifier qualifiers[])
NOT_SUPPORTED(fmi3GetIntervalFraction, const fmi3ValueReference vr[], size_t nvr, fmi3UInt64 counters[],
              fmi3UInt64 resolutions[], fmi3IntervalQualifier qualifiers[])
NOT_SUPPORTED(fmi3GetShiftDecimal, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 shifts[])
NOT_SUPPORTED(fmi3GetShiftFraction, const fmi3ValueReference vr[], size_t nvr, fmi3UInt64 counters[],
              fmi3UInt64 resolutions[])
NOT_SUPPORTED(fmi3SetIntervalDecimal, const fmi3ValueReference vr[], size_t nvr, const fmi3Float64 intervals[])
NOT_SUPPORTED(fmi3SetIntervalFraction, const fmi3ValueReference vr[], size_t nvr, const fmi3UInt64 counters[],
              const fmi3UInt64 resolutions[])
NOT_SUPPORTED(fmi3SetShiftDecimal, const fmi3ValueReference vr[], size_t nvr, const fmi3Float64 shifts[])
NOT_SUPPORTED(fmi3SetShiftFraction, const fmi3ValueReference vr[], size_t nvr, const fmi3UInt64 counters[],
              const fmi3UInt64 resolutions[])
NOT_SUPPORTED_0(fmi3EnterEventMode)
NOT_SUPPORTED_0(fmi3EvaluateDiscreteStates)
NOT_SUPPORTED(fmi3UpdateDiscreteStates, fmi3Boolean *discreteStatesNeedUpdate, fmi3Boolean *terminateSimulation,
              fmi3Boolean *nominalsChanged, fmi3Boolean *valuesChanged, fmi3Boolean *nextEventTimeDefined,
              fmi3Float64 *nextEventTime)
NOT_SUPPORTED_0(fmi3EnterContinuousTimeMode)
NOT_SUPPORTED(fmi3CompletedIntegratorStep, fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean *enterEventMode,
              fmi3Boolean *terminateSimulation)
NOT_SUPPORTED(fmi3SetTime, fmi3Float64 time)
NOT_SUPPORTED(fmi3SetContinuousStates, const fmi3Float64 states[], size_t n)
NOT_SUPPORTED(fmi3GetContinuousStateDerivatives, fmi3Float64 derivatives[], size_t n)
NOT_SUPPORTED(fmi3GetEventIndicators, fmi3Float64 indicators[], size_t n)
NOT_SUPPORTED(fmi3GetContinuousStates, fmi3Float64 states[], size_t n)
NOT_SUPPORTED(fmi3GetNominalsOfContinuousStates, fmi3Float64 nominals[], size_t n)
NOT_SUPPORTED(fmi3GetNumberOfEventIndicators, size_t *n)
NOT_SUPPORTED(fmi3GetNumberOfContinuousStates, size_t *n)
NOT_SUPPORTED_0(fmi3EnterStepMode)
NOT_SUPPORTED(fmi3GetOutputDerivatives, const fmi3ValueReference vr[], size_t nvr, const fmi3Int32 orders[],
              fmi3Float64 values[], size_t n)
NOT_SUPPORTED(fmi3ActivateModelPartition, fmi3ValueReference clock, fmi3Float64 time)

/* Model exchange and scheduled execution: no instance (the model description offers neither). */
FMI3_EXPORT fmi3Instance fmi3InstantiateModelExchange(fmi3String name, fmi3String token, fmi3String resources,
                                                      fmi3Boolean visible, fmi3Boolean loggingOn,
                                                      fmi3InstanceEnvironment environment, fmi3LogMessageCallback log) {
    (void)name; (void)token; (void)resources; (void)visible; (void)loggingOn;
    if (log) log(environment, fmi3Error, "logStatusError", "this FMU is for co-simulation only");
    return NULL;
}

FMI3_EXPORT fmi3Instance fmi3InstantiateScheduledExecution(fmi3String name, fmi3String token, fmi3String resources,
                                                           fmi3Boolean visible, fmi3Boolean loggingOn,
                                                           fmi3InstanceEnvironment environment,
                                                           fmi3LogMessageCallback log,
                                                           fmi3ClockUpdateCallback clockUpdate,
                                                           fmi3LockPreemptionCallback lock,
                                                           fmi3UnlockPreemptionCallback unlock) {
    (void)name; (void)token; (void)resources; (void)visible; (void)loggingOn; (void)clockUpdate; (void)lock;
    (void)unlock;
    if (log) log(environment, fmi3Error, "logStatusError", "this FMU is for co-simulation only");
    return NULL;
}
