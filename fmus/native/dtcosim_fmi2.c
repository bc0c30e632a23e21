/*
 * The linux64 binary of a dtcosim FMU: FMI 2.0 Co-Simulation in C, running the FMU's Python slave
 * (a pythonfmu Fmi2Slave subclass in resources/) through the CPython C API.
 *
 * It replaces pythonfmu's C++ wrapper, which needs the host to preload libpython (its binary does not
 * link it: "undefined symbol: _Py_NoneStruct" in C hosts), releases references it never took (the
 * work-arounds in fmus/slaves/base.py) and corrupts the heap a C host finds at exit. This file:
 *
 *  - finds Python itself, in this order: a Python already running in the host process (fmpy, any
 *    Python host: its symbols are global); else the library DTCOSIM_FMU_LIBPYTHON names; else the
 *    one recorded at build time in resources/python.txt; else the standard names of the recorded
 *    version (libpython3.X.so.1.0, libpython3.X.so). It is loaded with global symbols (numpy's
 *    extension modules need them);
 *  - starts that Python once per process with the recorded home (DTCOSIM_FMU_PYTHONHOME overrides)
 *    and the recorded environment's site-packages on sys.path (DTCOSIM_FMU_PYTHONPATH, ':'-separated,
 *    goes first), after checking that the home holds the standard library: a Python that cannot
 *    start is a NULL from fmi2Instantiate with a message naming what was looked for, never an abort
 *    of the host. It never finalises Python (the host process ends it);
 *  - holds the GIL for every call, so instances may live in several host threads;
 *  - forwards the slave's log queue to the host's logger with logging on (fmi2Instantiate's loggingOn
 *    or fmi2SetDebugLogging) and never without: fmpy keeps one process-wide logger callback whose
 *    target may be gone once logging is off (a call then crashes the host). Errors also go to
 *    stderr (the slaves echo theirs; this file those it finds itself);
 *  - maps the Python calls onto FMI statuses as pythonfmu does (an exception: its text logged, then
 *    fmi2Error; do_step returning False: fmi2Discard) and answers fmi2Terminated = false after a
 *    discarded step (the slave keeps its state at the step's start: fmi2LastSuccessfulTime).
 *
 * Built by fmus/binary.py with the C compiler the compiled kernels need, from this file, instance.c (an
 * instance and its calls into Python) and python_runtime.c (finding and starting Python):
 * cc -shared -fPIC -O2 -fvisibility=hidden *.c -ldl -lpthread (only the fmi2 functions are exported).
 * Needs no Python headers: the C API is reached through dlsym with the declarations in dtcosim_fmu.h.
 */
#include "dtcosim_fmu.h"

/* ------------------------------------------------------------ getters and setters */
static fmi2Status get_values(fmi2Component comp, const char *method, const fmi2ValueReference vr[], size_t nvr,
                             void *out, int kind) {
    Instance *c = (Instance *)comp;
    if (nvr == 0)
        return fmi2OK;
    int g = py.GILState_Ensure();
    PyObject *args[1] = {vr_list(vr, nvr)};
    PyObject *r = call(c, method, 1, args);
    fmi2Status s = fmi2OK;
    PyObject *list = r ? py.SequenceList(r) : NULL;
    if (r != NULL && (list == NULL || py.ListSize(list) != (Py_ssize_t)nvr)) {
        if (py.ErrOccurred()) py.ErrClear();
        say(&c->cb, c->logging_on, c->name, fmi2Error, "logStatusError", "%s returned %s values for %zu references", method,
            list ? "another number of" : "no list of", nvr);
        s = fmi2Error;
    } else if (r == NULL)
        s = fmi2Error;
    else {
        for (size_t i = 0; i < nvr; ++i) {
            PyObject *v = py.ListGetItem(list, (Py_ssize_t)i);
            switch (kind) {
            case 0: ((fmi2Real *)out)[i] = py.FloatAsDouble(v); break;
            case 1: ((fmi2Integer *)out)[i] = (fmi2Integer)py.LongAsLong(v); break;
            case 2: ((fmi2Boolean *)out)[i] = py.IsTrue(v) ? fmi2True : fmi2False; break;
            }
        }
        if (py.ErrOccurred()) {
            report_exception(c, method);
            s = fmi2Error;
        }
    }
    if (list) py.DecRef(list);
    if (r) py.DecRef(r);
    py.GILState_Release(g);
    return s;
}

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    return get_values(c, "get_real", vr, nvr, value, 0);
}
EXPORT fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[]) {
    return get_values(c, "get_integer", vr, nvr, value, 1);
}
EXPORT fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[]) {
    return get_values(c, "get_boolean", vr, nvr, value, 2);
}

/* strings returned by fmi2GetString stay valid until the next call on the instance */
static __thread char *string_store[256];

EXPORT fmi2Status fmi2GetString(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]) {
    Instance *c = (Instance *)comp;
    if (nvr == 0)
        return fmi2OK;
    if (nvr > 256) {
        say(&c->cb, c->logging_on, c->name, fmi2Error, "logStatusError", "fmi2GetString: at most 256 references per call");
        return fmi2Error;
    }
    int g = py.GILState_Ensure();
    PyObject *args[1] = {vr_list(vr, nvr)};
    PyObject *r = call(c, "get_string", 1, args);
    fmi2Status s = r ? fmi2OK : fmi2Error;
    PyObject *list = r ? py.SequenceList(r) : NULL;
    for (size_t i = 0; s == fmi2OK && i < nvr; ++i) {
        const char *t = list ? py.UnicodeAsUTF8(py.ListGetItem(list, (Py_ssize_t)i)) : NULL;
        if (t == NULL) {
            if (py.ErrOccurred()) py.ErrClear();
            s = fmi2Error;
            break;
        }
        free(string_store[i]);
        string_store[i] = copy_text(t);
        value[i] = string_store[i];
    }
    if (list) py.DecRef(list);
    if (r) py.DecRef(r);
    py.GILState_Release(g);
    return s;
}

static fmi2Status set_values(fmi2Component comp, const char *method, const fmi2ValueReference vr[], size_t nvr,
                             const void *in, int kind) {
    Instance *c = (Instance *)comp;
    if (nvr == 0)
        return fmi2OK;
    int g = py.GILState_Ensure();
    PyObject *values = py.ListNew((Py_ssize_t)nvr);
    for (size_t i = 0; i < nvr; ++i) {
        PyObject *v = NULL;
        switch (kind) {
        case 0: v = py.FloatFromDouble(((const fmi2Real *)in)[i]); break;
        case 1: v = py.LongFromLong(((const fmi2Integer *)in)[i]); break;
        case 2: v = py.BoolFromLong(((const fmi2Boolean *)in)[i]); break;
        case 3: v = py.UnicodeFromString(((const fmi2String *)in)[i] ? ((const fmi2String *)in)[i] : ""); break;
        }
        py.ListSetItem(values, (Py_ssize_t)i, v);
    }
    PyObject *args[2] = {vr_list(vr, nvr), values};
    PyObject *r = call(c, method, 2, args);
    fmi2Status s = r ? fmi2OK : fmi2Error;
    if (r) py.DecRef(r);
    py.GILState_Release(g);
    return s;
}

EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
    return set_values(c, "set_real", vr, nvr, value, 0);
}
EXPORT fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                 const fmi2Integer value[]) {
    return set_values(c, "set_integer", vr, nvr, value, 1);
}
EXPORT fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                 const fmi2Boolean value[]) {
    return set_values(c, "set_boolean", vr, nvr, value, 2);
}
EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]) {
    return set_values(c, "set_string", vr, nvr, value, 3);
}

/* ------------------------------------------------------------ FMU state */
EXPORT fmi2Status fmi2GetFMUstate(fmi2Component comp, fmi2FMUstate *state) {
    Instance *c = (Instance *)comp;
    int g = py.GILState_Ensure();
    PyObject *r = call(c, "_get_fmu_state", 0, NULL);
    py.GILState_Release(g);
    if (r == NULL)
        return fmi2Error;
    if (*state != NULL) { /* an earlier state given back for reuse */
        g = py.GILState_Ensure();
        py.DecRef((PyObject *)*state);
        py.GILState_Release(g);
    }
    *state = r;
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetFMUstate(fmi2Component comp, fmi2FMUstate state) {
    if (state == NULL)
        return fmi2Error;
    py.IncRef((PyObject *)state); /* consumed by call() */
    PyObject *args[1] = {(PyObject *)state};
    return simple_call(comp, "_set_fmu_state", 1, args);
}

EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component comp, fmi2FMUstate *state) {
    (void)comp;
    if (state == NULL || *state == NULL)
        return fmi2OK;
    int g = py.GILState_Ensure();
    py.DecRef((PyObject *)*state);
    py.GILState_Release(g);
    *state = NULL;
    return fmi2OK;
}

static PyObject *state_bytes(Instance *c, fmi2FMUstate state) {
    py.IncRef((PyObject *)state);
    PyObject *args[1] = {(PyObject *)state};
    return call(c, "_fmu_state_to_bytes", 1, args);
}

EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component comp, fmi2FMUstate state, size_t *size) {
    Instance *c = (Instance *)comp;
    int g = py.GILState_Ensure();
    PyObject *b = state ? state_bytes(c, state) : NULL;
    char *data = NULL;
    Py_ssize_t n = 0;
    fmi2Status s = (b && py.BytesAsStringAndSize(b, &data, &n) == 0) ? fmi2OK : fmi2Error;
    if (s != fmi2OK && py.ErrOccurred()) report_exception(c, "fmi2SerializedFMUstateSize");
    *size = (size_t)n;
    if (b) py.DecRef(b);
    py.GILState_Release(g);
    return s;
}

EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component comp, fmi2FMUstate state, fmi2Byte bytes[], size_t size) {
    Instance *c = (Instance *)comp;
    int g = py.GILState_Ensure();
    PyObject *b = state ? state_bytes(c, state) : NULL;
    char *data = NULL;
    Py_ssize_t n = 0;
    fmi2Status s = (b && py.BytesAsStringAndSize(b, &data, &n) == 0 && (size_t)n <= size) ? fmi2OK : fmi2Error;
    if (s == fmi2OK)
        memcpy(bytes, data, (size_t)n);
    else if (py.ErrOccurred())
        report_exception(c, "fmi2SerializeFMUstate");
    if (b) py.DecRef(b);
    py.GILState_Release(g);
    return s;
}

EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component comp, const fmi2Byte serializedState[], size_t size,
                                          fmi2FMUstate *state) {
    Instance *c = (Instance *)comp;
    int g = py.GILState_Ensure();
    PyObject *args[1] = {py.BytesFromStringAndSize(serializedState, (Py_ssize_t)size)};
    PyObject *r = call(c, "_fmu_state_from_bytes", 1, args);
    py.GILState_Release(g);
    if (r == NULL)
        return fmi2Error;
    *state = r;
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown[], size_t nU,
                                               const fmi2ValueReference vKnown[], size_t nK, const fmi2Real dvK[],
                                               fmi2Real dvU[]) {
    (void)vUnknown; (void)nU; (void)vKnown; (void)nK; (void)dvK; (void)dvU;
    Instance *i = (Instance *)c;
    say(&i->cb, i->logging_on, i->name, fmi2Error, "logStatusError", "fmi2GetDirectionalDerivative is not provided");
    return fmi2Error;
}

/* ------------------------------------------------------------ Co-Simulation */
EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                              const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr; (void)nvr; (void)order; (void)value;
    Instance *i = (Instance *)c;
    say(&i->cb, i->logging_on, i->name, fmi2Error, "logStatusError", "fmi2SetRealInputDerivatives: canInterpolateInputs is false");
    return fmi2Error;
}

EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                               const fmi2Integer order[], fmi2Real value[]) {
    (void)vr; (void)nvr; (void)order; (void)value;
    Instance *i = (Instance *)c;
    say(&i->cb, i->logging_on, i->name, fmi2Error, "logStatusError", "fmi2GetRealOutputDerivatives: maxOutputDerivativeOrder is 0");
    return fmi2Error;
}

EXPORT fmi2Status fmi2DoStep(fmi2Component comp, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                             fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    (void)noSetFMUStatePriorToCurrentPoint;
    Instance *c = (Instance *)comp;
    int g = py.GILState_Ensure();
    PyObject *args[2] = {py.FloatFromDouble(currentCommunicationPoint), py.FloatFromDouble(communicationStepSize)};
    PyObject *r = call(c, "do_step", 2, args);
    fmi2Status s;
    if (r == NULL)
        s = fmi2Error;
    else {
        int ok = py.IsTrue(r);
        py.DecRef(r);
        s = ok ? fmi2OK : fmi2Discard;
    }
    py.GILState_Release(g);
    c->discarded = s == fmi2Discard;
    c->step_start = currentCommunicationPoint;
    c->step_end = currentCommunicationPoint + communicationStepSize;
    return s;
}

EXPORT fmi2Status fmi2CancelStep(fmi2Component c) {
    (void)c;
    return fmi2Error; /* steps are never asynchronous (fmi2Pending is never returned) */
}

EXPORT fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    (void)c;
    if (s == fmi2DoStepStatus) {
        *value = fmi2OK;
        return fmi2OK;
    }
    return fmi2Discard;
}

EXPORT fmi2Status fmi2GetRealStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Real *value) {
    Instance *c = (Instance *)comp;
    if (s == fmi2LastSuccessfulTime) {
        *value = c->discarded ? c->step_start : c->step_end;
        return fmi2OK;
    }
    return fmi2Discard;
}

EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    (void)c; (void)s; (void)value;
    return fmi2Discard;
}

EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    (void)c;
    if (s == fmi2Terminated) {
        *value = fmi2False; /* a dtcosim slave never ends the simulation itself: a discard is a failed step */
        return fmi2OK;
    }
    return fmi2Discard;
}

EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    (void)c; (void)s; (void)value;
    return fmi2Discard;
}
