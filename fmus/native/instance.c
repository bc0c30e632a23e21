/* One instance of the dtcosim FMU: its Python slave, its calls, its life cycle (instantiate, set up, free). */
#include "dtcosim_fmu.h"

/* ----------------------------------------------------------------- the instance */


/* forward the slave's log queue; the GIL is held */
void flush_log(Instance *c) {
    if (c->log_queue == NULL)
        return;
    Py_ssize_t n = py.ListSize(c->log_queue);
    for (Py_ssize_t i = 0; i < n; ++i) {
        PyObject *m = py.ListGetItem(c->log_queue, i); /* borrowed */
        PyObject *st = py.GetAttrString(m, "status");
        PyObject *cat = py.GetAttrString(m, "category");
        PyObject *msg = py.GetAttrString(m, "msg");
        long status = st ? py.LongAsLong(st) : fmi2OK;
        const char *category = (cat && cat != py.None) ? py.UnicodeAsUTF8(cat) : "logAll";
        const char *text = msg ? py.UnicodeAsUTF8(msg) : "";
        if (py.ErrOccurred())
            py.ErrClear();
        if (c->logging_on && c->cb.logger != NULL)
            log_text(&c->cb, c->name, (fmi2Status)status, category ? category : "logAll", text ? text : "");
        if (st) py.DecRef(st);
        if (cat) py.DecRef(cat);
        if (msg) py.DecRef(msg);
    }
    if (n > 0)
        py.ListSetSlice(c->log_queue, 0, n, NULL);
}

/* the pending Python exception as text ("TypeError: ..."), logged; the GIL is held */
void report_exception(Instance *c, const char *what) {
    PyObject *type = NULL, *value = NULL, *tb = NULL;
    py.ErrFetch(&type, &value, &tb);
    py.ErrNormalize(&type, &value, &tb);
    const char *tname = "exception", *vtext = "";
    PyObject *tn = type ? py.GetAttrString(type, "__name__") : NULL;
    PyObject *vs = value ? py.Str(value) : NULL;
    if (tn) tname = py.UnicodeAsUTF8(tn);
    if (vs) vtext = py.UnicodeAsUTF8(vs);
    if (py.ErrOccurred())
        py.ErrClear();
    flush_log(c);
    /* a dtcosim slave raises FmuError after logging the message itself (and echoing it to stderr);
       anything else is logged here, to the logger only (the slave's runtime guard echoes import problems) */
    if (tname == NULL || strcmp(tname, "FmuError") != 0) {
        char text[8192];
        snprintf(text, sizeof text, "%s: %s: %s", what, tname ? tname : "exception", vtext ? vtext : "");
        if (c->logging_on && c->cb.logger != NULL)
            log_text(&c->cb, c->name, fmi2Error, "logStatusError", text);
        else
            fprintf(stderr, "%s: %s\n", c->name, text);
    }
    if (tn) py.DecRef(tn);
    if (vs) py.DecRef(vs);
    if (type) py.DecRef(type);
    if (value) py.DecRef(value);
    if (tb) py.DecRef(tb);
}

/* call slave.<method>(*args) (args: new references, consumed); NULL after an exception (reported) */
PyObject *call(Instance *c, const char *method, int nargs, PyObject **args) {
    PyObject *name = py.UnicodeFromString(method);
    PyObject *result = NULL;
    switch (nargs) {
    case 0: result = py.CallMethodObjArgs(c->slave, name, NULL); break;
    case 1: result = py.CallMethodObjArgs(c->slave, name, args[0], NULL); break;
    case 2: result = py.CallMethodObjArgs(c->slave, name, args[0], args[1], NULL); break;
    case 3: result = py.CallMethodObjArgs(c->slave, name, args[0], args[1], args[2], NULL); break;
    }
    py.DecRef(name);
    for (int i = 0; i < nargs; ++i)
        if (args[i]) py.DecRef(args[i]);
    if (result == NULL)
        report_exception(c, method);
    else
        flush_log(c);
    return result;
}

fmi2Status simple_call(fmi2Component comp, const char *method, int nargs, PyObject **args) {
    Instance *c = (Instance *)comp;
    int g = py.GILState_Ensure();
    PyObject *r = call(c, method, nargs, args);
    fmi2Status s = r ? fmi2OK : fmi2Error;
    if (r) py.DecRef(r);
    py.GILState_Release(g);
    return s;
}

PyObject *vr_list(const fmi2ValueReference vr[], size_t n) {
    PyObject *l = py.ListNew((Py_ssize_t)n);
    for (size_t i = 0; i < n; ++i)
        py.ListSetItem(l, (Py_ssize_t)i, py.LongFromLong((long)vr[i]));
    return l;
}

char *copy_text(const char *s) {
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d) memcpy(d, s, n);
    return d;
}

static void read_line(const char *file, char *out, size_t size) {
    out[0] = '\0';
    FILE *fh = fopen(file, "r");
    if (fh == NULL)
        return;
    if (fgets(out, (int)size, fh) == NULL)
        out[0] = '\0';
    out[strcspn(out, "\r\n")] = '\0';
    fclose(fh);
}

/* file:///a/b -> /a/b (percent-decoded); a plain path stays */
static void uri_to_path(const char *uri, char *out, size_t size) {
    const char *p = uri;
    if (strncmp(p, "file://", 7) == 0) {
        p += 7;
        if (strncmp(p, "localhost/", 10) == 0)
            p += 9;
    } else if (strncmp(p, "file:", 5) == 0)
        p += 5;
    size_t k = 0;
    for (; *p && k + 1 < size; ++p) {
        if (p[0] == '%' && p[1] && p[2]) {
            char hex[3] = {p[1], p[2], 0};
            out[k++] = (char)strtol(hex, NULL, 16);
            p += 2;
        } else
            out[k++] = *p;
    }
    out[k] = '\0';
    while (k > 1 && out[k - 1] == '/')
        out[--k] = '\0';
}

/* ----------------------------------------------------------------- FMI 2.0 functions */
EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

EXPORT fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                                     fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                                     fmi2Boolean visible, fmi2Boolean loggingOn) {
    (void)fmuGUID;
    if (fmuType != fmi2CoSimulation) {
        say(functions, loggingOn, instanceName, fmi2Error, "logStatusError", "this FMU supports Co-Simulation only");
        return NULL;
    }
    if (fmuResourceLocation == NULL) {
        say(functions, loggingOn, instanceName, fmi2Error, "logStatusError", "no fmuResourceLocation given");
        return NULL;
    }
    char resources[2048];
    uri_to_path(fmuResourceLocation, resources, sizeof resources);
    if (!start_python(resources)) {
        say(functions, loggingOn, instanceName, fmi2Error, "logStatusError", "cannot start Python: %s", python_start_problem());
        return NULL;
    }
    char file[2300], module[512], class_name[256];
    snprintf(file, sizeof file, "%s/slavemodule.txt", resources);
    read_line(file, module, sizeof module);
    snprintf(file, sizeof file, "%s/slaveclass.txt", resources);
    read_line(file, class_name, sizeof class_name);
    if (module[0] == '\0' || class_name[0] == '\0') {
        say(functions, loggingOn, instanceName, fmi2Error, "logStatusError",
            "%s has no slavemodule.txt or slaveclass.txt: not a dtcosim FMU's resources", resources);
        return NULL;
    }
    Instance *c = calloc(1, sizeof *c);
    if (c == NULL)
        return NULL;
    c->name = copy_text(instanceName ? instanceName : "");
    c->resources = copy_text(resources);
    c->module = copy_text(module);
    c->class_name = copy_text(class_name);
    if (functions != NULL)
        c->cb = *functions;
    c->logging_on = loggingOn ? 1 : 0;

    int g = py.GILState_Ensure();
    PyObject *path = py.SysGetObject("path");
    int present = 0;
    if (path != NULL) {
        Py_ssize_t n = py.ListSize(path);
        for (Py_ssize_t i = 0; i < n && !present; ++i) {
            const char *s = py.UnicodeAsUTF8(py.ListGetItem(path, i));
            present = s != NULL && strcmp(s, resources) == 0;
        }
        if (py.ErrOccurred())
            py.ErrClear();
    }
    if (!present)
        add_path(resources, 1);
    PyObject *mod = py.ImportModule(module);
    PyObject *cls = mod ? py.GetAttrString(mod, class_name) : NULL;
    PyObject *slave = NULL;
    if (cls != NULL) {
        PyObject *args = py.TupleNew(0);
        PyObject *kw = py.DictNew();
        PyObject *v;
        py.DictSetItemString(kw, "instance_name", v = py.UnicodeFromString(c->name)); py.DecRef(v);
        py.DictSetItemString(kw, "resources", v = py.UnicodeFromString(resources)); py.DecRef(v);
        py.DictSetItemString(kw, "visible", v = py.BoolFromLong(visible)); py.DecRef(v);
        slave = py.CallObject(cls, args, kw);
        py.DecRef(args);
        py.DecRef(kw);
    }
    if (slave == NULL) {
        report_exception(c, mod == NULL ? "import of the slave module" : "creation of the slave");
        if (cls) py.DecRef(cls);
        if (mod) py.DecRef(mod);
        py.GILState_Release(g);
        free(c->name); free(c->resources); free(c->module); free(c->class_name); free(c);
        return NULL;
    }
    py.DecRef(cls);
    py.DecRef(mod);
    c->slave = slave;
    c->log_queue = py.GetAttrString(slave, "log_queue");
    if (c->log_queue == NULL)
        py.ErrClear();
    flush_log(c);
    py.GILState_Release(g);
    return c;
}

EXPORT void fmi2FreeInstance(fmi2Component comp) {
    Instance *c = (Instance *)comp;
    if (c == NULL)
        return;
    int g = py.GILState_Ensure();
    flush_log(c);
    if (c->log_queue) py.DecRef(c->log_queue);
    if (c->slave) py.DecRef(c->slave);
    py.GILState_Release(g);
    free(c->name); free(c->resources); free(c->module); free(c->class_name); free(c);
}

EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component comp, fmi2Boolean loggingOn, size_t nCategories,
                                      const fmi2String categories[]) {
    (void)nCategories;
    (void)categories;
    ((Instance *)comp)->logging_on = loggingOn ? 1 : 0;
    return fmi2OK;
}

EXPORT fmi2Status fmi2SetupExperiment(fmi2Component comp, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                                      fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    Instance *c = (Instance *)comp;
    int g = py.GILState_Ensure();
    PyObject *args[3];
    args[0] = py.FloatFromDouble(startTime);
    if (stopTimeDefined) args[1] = py.FloatFromDouble(stopTime);
    else { py.IncRef(py.None); args[1] = py.None; }
    if (toleranceDefined) args[2] = py.FloatFromDouble(tolerance);
    else { py.IncRef(py.None); args[2] = py.None; }
    c->step_start = c->step_end = startTime;
    py.GILState_Release(g);
    return simple_call(comp, "setup_experiment", 3, args);
}

EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component comp) {
    return simple_call(comp, "enter_initialization_mode", 0, NULL);
}

EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component comp) {
    return simple_call(comp, "exit_initialization_mode", 0, NULL);
}

EXPORT fmi2Status fmi2Terminate(fmi2Component comp) { return simple_call(comp, "terminate", 0, NULL); }

EXPORT fmi2Status fmi2Reset(fmi2Component comp) {
    Instance *c = (Instance *)comp;
    int g = py.GILState_Ensure();
    PyObject *cls = py.GetAttrString(c->slave, "__class__");
    PyObject *fresh = NULL;
    if (cls != NULL) {
        PyObject *args = py.TupleNew(0), *kw = py.DictNew(), *v;
        py.DictSetItemString(kw, "instance_name", v = py.UnicodeFromString(c->name)); py.DecRef(v);
        py.DictSetItemString(kw, "resources", v = py.UnicodeFromString(c->resources)); py.DecRef(v);
        fresh = py.CallObject(cls, args, kw);
        py.DecRef(args);
        py.DecRef(kw);
        py.DecRef(cls);
    }
    fmi2Status s = fmi2OK;
    if (fresh == NULL) {
        report_exception(c, "reset");
        s = fmi2Error;
    } else {
        flush_log(c);
        if (c->log_queue) py.DecRef(c->log_queue);
        py.DecRef(c->slave);
        c->slave = fresh;
        c->log_queue = py.GetAttrString(fresh, "log_queue");
        if (c->log_queue == NULL) py.ErrClear();
        c->discarded = 0;
    }
    py.GILState_Release(g);
    return s;
}

