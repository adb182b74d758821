/* The guard in front of the Python FMU: binaries/linux64/<modelIdentifier>.so is this library,
   pythonfmu's binary ships beside it under the name resources/guard.txt gives.

   Why: pythonfmu's C++ wrapper turns every Python exception into fmi2Fatal (get/set) or
   fmi2Discard (doStep), so the slave can refuse a call but cannot answer fmi2Error. The guard
   refuses the calls the standard forbids with fmi2Error and the reason logged (the checks of
   variables.h, the same as the standalone FMU's) and forwards every other call unchanged.

   And: pythonfmu's binary does not link libpython, it expects Python in the host process. When
   the process has none (Py_IsInitialized not found), the guard loads libpython with RTLD_GLOBAL
   first: $NODEFORCE_LIBPYTHON if set (a user's choice, nothing else is tried), else the first
   that loads of the path recorded at export in resources/guard.txt, the libpython of the
   python3 on PATH (its sysconfig), the recorded file name through the dynamic linker's search
   (LD_LIBRARY_PATH, ld.so.cache: a system Python of the exporting version), and that name in
   /usr/local/lib and $CONDA_PREFIX/lib; the logged error names every one tried.

   The guard does not depend on the model: it reads the sizes of the layout from
   resources/guard.txt at instantiation (and the variables' names from resources/names.txt, for
   its messages), a file of four lines:
       nodeforce-guard/1
       sizes N N_IN N_PAR
       binary FILE_NAME         pythonfmu's binary, in this library's folder
       libpython PATH

   Loading. pythonfmu's binary is opened once per load of this library, RTLD_LOCAL: its fmi2*
   names, the same as ours, then stay out of the global scope, and we call it only through the
   pointers dlsym gives. Its own calls cannot land here either: it has no relocations against
   fmi2* names (objdump -R), so RTLD_DEEPBIND, which would also give it a C++ runtime scope of
   its own, is not needed. It is never closed: glibc cannot unload it anyway (its GNU unique
   symbols make it RTLD_NODELETE), and pythonfmu ends the interpreter it started when it is
   unloaded, which numpy does not survive between two instances.

   Two defects of pythonfmu 0.7.0's binary corrupt the host's memory; the guard keeps the host
   out of both (tests/test_fmu_memory.py shows each):
   - At process exit it releases its Python state twice: its static destructor frees the state,
     then its ELF destructor (finalizePythonInterpreter) releases the freed state again, and
     glibc later reports "corrupted double-linked list" or nothing, by chance. The guard calls
     finalizePythonInterpreter itself from an exit handler registered after pythonfmu's static
     destructors, so it runs first: the state is released once, the later calls find it empty.
     The guard stays loaded to the end of the process (RTLD_NODELETE) so that its handler does.
   - When the model raises, it releases the instance's Python objects, answers fmi2Fatal, and
     releases them again in the next call that touches them (fmi2Reset, fmi2FreeInstance). The
     guard sets that instance aside, never calls it again (its few bytes are left allocated),
     and answers fmi2Error, as for any failed call of this instance: fmi2Reset instantiates the
     model anew, fmi2FreeInstance frees the rest.

   Outputs: a host may read the N outputs one value per fmi2GetReal (the FMI Compliance Checker
   does), and each call into pythonfmu costs tens of microseconds of Python. The outputs change
   only in the calls that step or move the slave (fmi2DoStep, the state changes, fmi2Reset,
   fmi2SetFMUstate; variables.h refuses setting them), so the guard reads all N in one call the
   first time one is asked for after such a call, once initialisation has ended, and answers
   every read of outputs only from that copy until the next such call
   (benchmarks/bench_fmu_calls.py). */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2.h"
#include "glibc.h"
#include "resources.h"
#include "variables.h"


#define LIBPYTHON_VARIABLE "NODEFORCE_LIBPYTHON"

#define FORWARDED(X)                                                                                          \
    X(fmi2SetDebugLogging) X(fmi2Instantiate) X(fmi2FreeInstance) X(fmi2SetupExperiment)                      \
    X(fmi2EnterInitializationMode) X(fmi2ExitInitializationMode) X(fmi2Terminate) X(fmi2Reset) X(fmi2GetReal) \
    X(fmi2GetInteger) X(fmi2GetBoolean) X(fmi2GetString) X(fmi2SetReal) X(fmi2SetInteger) X(fmi2SetBoolean)   \
    X(fmi2SetString) X(fmi2GetFMUstate) X(fmi2SetFMUstate) X(fmi2FreeFMUstate) X(fmi2SerializedFMUstateSize)  \
    X(fmi2SerializeFMUstate) X(fmi2DeSerializeFMUstate) X(fmi2GetDirectionalDerivative)                       \
    X(fmi2SetRealInputDerivatives) X(fmi2GetRealOutputDerivatives) X(fmi2DoStep) X(fmi2CancelStep)            \
    X(fmi2GetStatus) X(fmi2GetRealStatus) X(fmi2GetIntegerStatus) X(fmi2GetBooleanStatus) X(fmi2GetStringStatus)

#define MEMBER(name) name##TYPE *name;
static struct {
    void *library;
    void (*finalize)(void); /* pythonfmu's finalizePythonInterpreter, if it has one */
    FORWARDED(MEMBER)
} inner;
static pthread_mutex_t loading = PTHREAD_MUTEX_INITIALIZER;

typedef struct {
    fmi2Component inner;
    int lost; /* the model raised: `inner` is set aside (see the top of this file) */
    Layout layout;
    int cached;                      /* `outputs` holds the outputs since the last step or state change */
    fmi2Real *outputs;               /* T[1..N] */
    fmi2ValueReference *output_refs; /* their value references */
    int state;
    double time; /* the current communication point (s), for the messages */
    char *name, *guid, *resources;
    fmi2Type type;
    fmi2Boolean visible, logging;
    const fmi2CallbackFunctions *functions; /* the host's: valid until fmi2FreeInstance (FMI 2.0) */
} Guard;

/* A state of the slave: the guard's state and time beside pythonfmu's. */
typedef struct {
    int state;
    double time;
    fmi2FMUstate inner;
} GuardState;

static void log_error(const fmi2CallbackFunctions *cb, const char *name, const char *format, ...) {
    char message[8192];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    if (cb && cb->logger) cb->logger(cb->componentEnvironment, name, fmi2Error, "logStatusError", "%s", message);
}

/* ------------------------------------------------------------------ resources/guard.txt */
typedef struct {
    Layout layout;
    char binary[256];
    char libpython[4096];
} GuardFile;

/* The rest of a line after "word ", without its newline. */
static int read_field(FILE *f, const char *word, char *value, size_t size) {
    char line[4352];
    size_t n = strlen(word), length;
    if (!fgets(line, sizeof line, f) || strncmp(line, word, n) != 0 || line[n] != ' ') return 0;
    length = strcspn(line + n + 1, "\r\n");
    if (length == 0 || length >= size) return 0;
    memcpy(value, line + n + 1, length);
    value[length] = 0;
    return 1;
}

static int read_guard_file(const char *path, GuardFile *g) {
    char header[64], sizes[64];
    FILE *f = fopen(path, "r");
    int ok = f && fgets(header, sizeof header, f) && strcmp(header, "nodeforce-guard/1\n") == 0
             && read_field(f, "sizes", sizes, sizeof sizes) && read_sizes(sizes, &g->layout)
             && read_field(f, "binary", g->binary, sizeof g->binary)
             && read_field(f, "libpython", g->libpython, sizeof g->libpython);
    if (f) fclose(f);
    return ok;
}

/* ------------------------------------------------------------------ finding libpython */
/* Load `path` RTLD_GLOBAL; else add "path (why)" to the list of what was tried. */
static int try_python(const char *path, char *tried, size_t size) {
    size_t used = strlen(tried);
    if (dlopen(path, RTLD_NOW | RTLD_GLOBAL)) return 1;
    snprintf(tried + used, size - used, "%s%s (%s)", used ? "; " : "", path, dlerror());
    return 0;
}

/* The libpython of the python3 on PATH, from its sysconfig, into `path`; 0 without one. */
static int python_on_path(char *path, size_t size) {
    FILE *p = popen("python3 -c \"import os, sysconfig as s; print(os.path.join(s.get_config_var('LIBDIR') or '', "
                    "s.get_config_var('INSTSONAME') or ''))\" 2>/dev/null", "r");
    int ok;
    if (!p) return 0;
    ok = fgets(path, (int)size, p) != NULL;
    if (pclose(p) != 0) ok = 0;
    path[strcspn(path, "\r\n")] = 0;
    return ok && path[0] == '/';
}

/* libpython without $NODEFORCE_LIBPYTHON: the candidates of the top of this file, in turn. */
static int load_python(const char *recorded, const fmi2CallbackFunctions *cb, const char *name) {
    char tried[6144] = "", path[4352];
    const char *slash = strrchr(recorded, '/'), *file = slash ? slash + 1 : recorded;
    const char *folders[2] = {"/usr/local/lib", getenv("CONDA_PREFIX")};
    size_t used, k;
    if (try_python(recorded, tried, sizeof tried)) return 1;
    if (python_on_path(path, sizeof path)) {
        if (try_python(path, tried, sizeof tried)) return 1;
    } else {
        used = strlen(tried);
        snprintf(tried + used, sizeof tried - used, "; python3 on PATH (none, or it gives no shared libpython)");
    }
    if (try_python(file, tried, sizeof tried)) return 1; /* the dynamic linker's search */
    for (k = 0; k < 2; k++) {
        if (!folders[k] || !*folders[k]) continue;
        snprintf(path, sizeof path, "%s%s/%s", folders[k], k ? "/lib" : "", file);
        if (try_python(path, tried, sizeof tried)) return 1;
    }
    log_error(cb, name, "this process has no Python and no libpython could be loaded; tried %s unset, then %s: set %s "
              "to the libpython3 shared library of a Python with numpy", LIBPYTHON_VARIABLE, tried, LIBPYTHON_VARIABLE);
    return 0;
}

/* ------------------------------------------------------------------ loading pythonfmu's binary */
static void here(void) {}

/* The exit handler of the top of this file: pythonfmu's state released once, before its
   static destructors run. */
static void release_python(void) { inner.finalize(); }

/* Python in the process, then pythonfmu's binary and its functions; 0 with the reason logged. */
static int load(const GuardFile *file, const fmi2CallbackFunctions *cb, const char *name) {
    Dl_info self;
    char *path;
    const char *slash, *libpython = getenv(LIBPYTHON_VARIABLE);
    void *library;
    if (inner.library) return 1;
    if (!dlsym(RTLD_DEFAULT, "Py_IsInitialized")) {
        if (libpython && *libpython) {
            if (!dlopen(libpython, RTLD_NOW | RTLD_GLOBAL)) {
                log_error(cb, name, "this process has no Python and libpython cannot be loaded (%s): set %s to the "
                          "libpython3 shared library of a Python with numpy", dlerror(), LIBPYTHON_VARIABLE);
                return 0;
            }
        } else if (!load_python(file->libpython, cb, name)) {
            return 0;
        }
    }
    if (!dladdr((void *)here, &self) || !(slash = strrchr(self.dli_fname, '/'))) {
        log_error(cb, name, "cannot find the folder of the FMU's binary");
        return 0;
    }
    path = malloc((size_t)(slash - self.dli_fname) + strlen(file->binary) + 2);
    if (!path) return 0;
    sprintf(path, "%.*s/%s", (int)(slash - self.dli_fname), self.dli_fname, file->binary);
    library = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    free(path);
    if (!library) {
        log_error(cb, name, "cannot load pythonfmu's binary: %s", dlerror());
        return 0;
    }
#define LOOK_UP(function)                                                              \
    if (!(inner.function = (function##TYPE *)dlsym(library, #function))) {           \
        log_error(cb, name, "pythonfmu's binary has no function %s", #function);      \
        dlclose(library);                                                              \
        return 0;                                                                      \
    }
    FORWARDED(LOOK_UP)
    inner.library = library;
    inner.finalize = (void (*)(void))dlsym(library, "finalizePythonInterpreter");
    if (inner.finalize && dlopen(self.dli_fname, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE)) atexit(release_python);
    return 1;
}

/* ------------------------------------------------------------------ FMI 2.0 */
#define LOST "the model raised an exception (pythonfmu logs it when logging is on): this instance answers " \
             "fmi2Error until fmi2Reset or fmi2FreeInstance"

static fmi2Status refuse(Guard *g, const char *reason) {
    log_error(g->functions, g->name, "%s", reason);
    return fmi2Error;
}

/* pythonfmu's answer, but fmi2Fatal, which sets the instance aside (the top of this file). */
static fmi2Status answered(Guard *g, fmi2Status status) {
    if (status != fmi2Fatal) return status;
    g->lost = 1;
    return refuse(g, LOST);
}

/* A call forwarded to pythonfmu's instance, unless it is set aside. */
#define FORWARD(g, call) ((g)->lost ? refuse((g), LOST) : answered((g), inner.call))

/* A state change that happens when the slave accepts the call. */
static fmi2Status moved(Guard *g, fmi2Status status, int state) {
    g->cached = 0;
    if (status <= fmi2Warning) g->state = state;
    return status;
}

FMI2_EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
FMI2_EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

FMI2_EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String categories[]) {
    Guard *g = c;
    return FORWARD(g, fmi2SetDebugLogging(g->inner, on, n, categories));
}

static char *copy(const char *text) {
    char *copied = malloc(strlen(text ? text : "") + 1);
    if (copied) strcpy(copied, text ? text : "");
    return copied;
}

static void free_guard(Guard *g) {
    if (!g) return;
    free(g->name);
    free(g->guid);
    free(g->resources);
    free(g->outputs);
    free(g->output_refs);
    free_names(&g->layout);
    free(g);
}

/* pythonfmu's instance of the model, made from what the guard keeps of fmi2Instantiate. */
static fmi2Component instantiate(Guard *g) {
    return inner.fmi2Instantiate(g->name, g->type, g->guid, g->resources, g->functions, g->visible, g->logging);
}

FMI2_EXPORT fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                                          const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                                          fmi2Boolean loggingOn) {
    GuardFile file;
    Guard *g;
    char *path;
    int ok, k;
    if (!functions) return NULL; /* no logger to say why: the standard requires the callbacks */
    path = resources ? resource_path(resources, "guard.txt") : NULL;
    ok = path && read_guard_file(path, &file);
    if (!ok) {
        log_error(functions, name, "cannot read %s", path ? path : "the resources (no fmuResourceLocation)");
        free(path);
        return NULL;
    }
    free(path);
    pthread_mutex_lock(&loading);
    ok = load(&file, functions, name);
    pthread_mutex_unlock(&loading);
    g = ok ? calloc(1, sizeof(Guard)) : NULL;
    if (!g) return NULL;
    g->name = copy(name);
    g->guid = copy(guid);
    g->resources = copy(resources);
    g->type = type;
    g->visible = visible;
    g->logging = loggingOn;
    g->functions = functions;
    g->layout = file.layout;
    g->state = INSTANTIATED;
    path = resource_path(resources, "names.txt");
    if (!read_names(&g->layout, path)) free_names(&g->layout); /* messages then say "an input" */
    free(path);
    g->outputs = malloc(sizeof(fmi2Real) * (size_t)(file.layout.n + 1));
    g->output_refs = malloc(sizeof(fmi2ValueReference) * (size_t)(file.layout.n + 1));
    for (k = 0; g->output_refs && k < file.layout.n; k++) g->output_refs[k] = (fmi2ValueReference)(vr_T(&g->layout) + k);
    g->inner = g->name && g->guid && g->resources && g->outputs && g->output_refs ? instantiate(g) : NULL;
    if (!g->inner) {
        free_guard(g);
        return NULL;
    }
    return g;
}

FMI2_EXPORT void fmi2FreeInstance(fmi2Component c) {
    Guard *g = c;
    if (!g) return;
    if (!g->lost) inner.fmi2FreeInstance(g->inner);
    free_guard(g);
}

FMI2_EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                                           fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    Guard *g = c;
    fmi2Status status = FORWARD(g, fmi2SetupExperiment(g->inner, toleranceDefined, tolerance, startTime,
                                                       stopTimeDefined, stopTime));
    if (status <= fmi2Warning) g->time = startTime;
    return status;
}

/* The calls that move the instance to another state: forwarded, the state kept if they succeed. */
#define MOVES_TO(function, to)                                 \
    FMI2_EXPORT fmi2Status function(fmi2Component c) {         \
        Guard *g = c;                                          \
        return moved(g, FORWARD(g, function(g->inner)), to);   \
    }
MOVES_TO(fmi2EnterInitializationMode, INITIALISATION)
MOVES_TO(fmi2ExitInitializationMode, STEPPING)
MOVES_TO(fmi2Terminate, TERMINATED)

/* After a failed call, fmi2Reset is how the standard lets the host go on: an instance set aside
   is replaced by a new one. */
FMI2_EXPORT fmi2Status fmi2Reset(fmi2Component c) {
    Guard *g = c;
    fmi2Component fresh;
    g->time = 0.0;
    if (!g->lost) return moved(g, answered(g, inner.fmi2Reset(g->inner)), INSTANTIATED);
    fresh = instantiate(g);
    if (!fresh) return refuse(g, "fmi2Reset: the model cannot be instantiated again");
    g->inner = fresh;
    g->lost = 0;
    g->cached = 0;
    g->state = INSTANTIATED;
    return fmi2OK;
}

/* The get and set calls: refused here (variables.h), or forwarded. */
#define GET_OR_SET(function, value_type, reals, real, setting)                                                \
    FMI2_EXPORT fmi2Status function(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, value_type) { \
        Guard *g = c;                                                                                         \
        char message[512];                                                                                    \
        if (refused2(&g->layout, vr, nvr, reals, real, setting, g->state, g->time, message, sizeof message)) \
            return refuse(g, message);                                                                        \
        return FORWARD(g, function(g->inner, vr, nvr, value));                                                \
    }
GET_OR_SET(fmi2SetReal, const fmi2Real value[], value, 1, 1)
GET_OR_SET(fmi2GetBoolean, fmi2Boolean value[], NULL, 0, 0)
GET_OR_SET(fmi2SetBoolean, const fmi2Boolean value[], NULL, 0, 1)

/* Outputs only, once initialisation has ended: from the copy (the top of this file). */
FMI2_EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    Guard *g = c;
    char message[512];
    size_t k;
    int outputs = (g->state == STEPPING || g->state == TERMINATED) && !g->lost;
    if (refused2(&g->layout, vr, nvr, NULL, 1, 0, g->state, g->time, message, sizeof message))
        return refuse(g, message);
    for (k = 0; outputs && k < nvr; k++) outputs = (int)vr[k] >= vr_T(&g->layout) && (int)vr[k] < vr_parameters(&g->layout);
    if (!outputs) return FORWARD(g, fmi2GetReal(g->inner, vr, nvr, value));
    if (!g->cached) {
        fmi2Status status = FORWARD(g, fmi2GetReal(g->inner, g->output_refs, (size_t)g->layout.n, g->outputs));
        if (status > fmi2Warning) return status;
        g->cached = 1;
    }
    for (k = 0; k < nvr; k++) value[k] = g->outputs[vr[k] - (fmi2ValueReference)vr_T(&g->layout)];
    return fmi2OK;
}

#define NO_SUCH_TYPE(function, value_type, type)                                                              \
    FMI2_EXPORT fmi2Status function(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, value_type) { \
        Guard *g = c;                                                                                         \
        char reason[256];                                                                                     \
        if (no_such_type(type, nvr, reason, sizeof reason)) return refuse(g, reason);                        \
        return FORWARD(g, function(g->inner, vr, nvr, value));                                                \
    }
NO_SUCH_TYPE(fmi2GetInteger, fmi2Integer value[], "Integer")
NO_SUCH_TYPE(fmi2SetInteger, const fmi2Integer value[], "Integer")
NO_SUCH_TYPE(fmi2GetString, fmi2String value[], "String")
NO_SUCH_TYPE(fmi2SetString, const fmi2String value[], "String")

FMI2_EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *state) {
    Guard *g = c;
    GuardState *s = *state ? *state : calloc(1, sizeof(GuardState));
    fmi2Status status;
    if (!s) return refuse(g, "out of memory for a state");
    status = FORWARD(g, fmi2GetFMUstate(g->inner, &s->inner));
    if (status > fmi2Warning) {
        if (!*state) free(s);
        return status;
    }
    s->state = g->state;
    s->time = g->time;
    *state = s;
    return status;
}

FMI2_EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state) {
    Guard *g = c;
    GuardState *s = state;
    fmi2Status status;
    if (!s) return refuse(g, "fmi2SetFMUstate without a state");
    status = moved(g, FORWARD(g, fmi2SetFMUstate(g->inner, s->inner)), s->state);
    if (status <= fmi2Warning) g->time = s->time;
    return status;
}

/* Allowed on an instance set aside too: pythonfmu's fmi2FreeFMUstate releases the state's own
   Python object and touches nothing of the instance. */
FMI2_EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state) {
    Guard *g = c;
    GuardState *s = *state;
    fmi2Status status = fmi2OK;
    if (!s) return fmi2OK;
    if (s->inner) status = inner.fmi2FreeFMUstate(g->inner, &s->inner);
    free(s);
    *state = NULL;
    return status;
}

/* A serialized state: one byte of the guard's state, then pythonfmu's bytes. */
FMI2_EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t *size) {
    Guard *g = c;
    fmi2Status status = FORWARD(g, fmi2SerializedFMUstateSize(g->inner, ((GuardState *)state)->inner, size));
    if (status <= fmi2Warning) *size += 1;
    return status;
}

FMI2_EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state, fmi2Byte bytes[], size_t size) {
    Guard *g = c;
    GuardState *s = state;
    if (size < 1) return refuse(g, "fmi2SerializeFMUstate: no room for the state");
    bytes[0] = (fmi2Byte)s->state;
    return FORWARD(g, fmi2SerializeFMUstate(g->inner, s->inner, bytes + 1, size - 1));
}

FMI2_EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size,
                                               fmi2FMUstate *state) {
    Guard *g = c;
    GuardState *s;
    fmi2Status status;
    if (size < 1 || bytes[0] < INSTANTIATED || bytes[0] > TERMINATED)
        return refuse(g, "these bytes are not a serialized state of this FMU");
    s = calloc(1, sizeof(GuardState));
    if (!s) return refuse(g, "out of memory for a state");
    s->state = bytes[0];
    status = FORWARD(g, fmi2DeSerializeFMUstate(g->inner, bytes + 1, size - 1, &s->inner));
    if (status > fmi2Warning) {
        free(s);
        return status;
    }
    *state = s;
    return status;
}

FMI2_EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                                    const fmi2ValueReference z[], size_t nz, const fmi2Real dv[],
                                                    fmi2Real dz[]) {
    Guard *g = c;
    return FORWARD(g, fmi2GetDirectionalDerivative(g->inner, u, nu, z, nz, dv, dz));
}

/* pythonfmu answers fmi2SetRealInputDerivatives with an error: the guard sets the derivatives as
   the slave's undeclared values after the declared ones (fmu_build/variables.py, `derivatives`:
   input or T_forced r at layout_size + r - vr_inputs). */
FMI2_EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                                   const fmi2Integer order[], const fmi2Real value[]) {
    Guard *g = c;
    char message[512];
    fmi2ValueReference *hidden;
    fmi2Status status;
    size_t k;
    if (derivative_refusal(&g->layout, vr, nvr, order, value, g->state, g->time, message, sizeof message))
        return refuse(g, message);
    if (nvr == 0) return fmi2OK;
    hidden = malloc(sizeof *hidden * nvr);
    if (!hidden) return refuse(g, "out of memory");
    for (k = 0; k < nvr; k++)
        hidden[k] = (fmi2ValueReference)(layout_size(&g->layout) + (int)vr[k] - vr_inputs(&g->layout));
    status = FORWARD(g, fmi2SetReal(g->inner, hidden, nvr, value));
    free(hidden);
    return status;
}

FMI2_EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                                    const fmi2Integer order[], fmi2Real value[]) {
    Guard *g = c;
    return FORWARD(g, fmi2GetRealOutputDerivatives(g->inner, vr, nvr, order, value));
}

FMI2_EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                                  fmi2Real communicationStepSize, fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    Guard *g = c;
    char reason[256];
    fmi2Status status;
    if (step_refusal(g->state, communicationStepSize, reason, sizeof reason)) return refuse(g, reason);
    g->cached = 0;
    status = FORWARD(g, fmi2DoStep(g->inner, currentCommunicationPoint, communicationStepSize,
                                   noSetFMUStatePriorToCurrentPoint));
    if (status <= fmi2Warning) g->time = currentCommunicationPoint + communicationStepSize;
    return status;
}

FMI2_EXPORT fmi2Status fmi2CancelStep(fmi2Component c) {
    Guard *g = c;
    return FORWARD(g, fmi2CancelStep(g->inner));
}

#define STATUS(function, value_type)                                                              \
    FMI2_EXPORT fmi2Status function(fmi2Component c, const fmi2StatusKind s, value_type *value) { \
        Guard *g = c;                                                                             \
        return FORWARD(g, function(g->inner, s, value));                                          \
    }
STATUS(fmi2GetStatus, fmi2Status)
STATUS(fmi2GetRealStatus, fmi2Real)
STATUS(fmi2GetIntegerStatus, fmi2Integer)
STATUS(fmi2GetBooleanStatus, fmi2Boolean)
STATUS(fmi2GetStringStatus, fmi2String)
