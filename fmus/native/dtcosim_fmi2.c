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
 * Built by fmus/native.py with the C compiler the compiled kernels need: cc -shared -fPIC -O2 -ldl.
 * Needs no Python headers: the C API is reached through dlsym with the declarations below.
 */
#include <dlfcn.h>
#include <pthread.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <wchar.h>

/* ----------------------------------------------------------------- FMI 2.0 types (fmi2TypesPlatform.h) */
typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char *fmi2String;
typedef char fmi2Byte;
#define fmi2True 1
#define fmi2False 0

typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum { fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime, fmi2Terminated } fmi2StatusKind;

typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...);
typedef struct {
    fmi2CallbackLogger logger;
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

#define EXPORT __attribute__((visibility("default")))

/* ----------------------------------------------------------------- the CPython C API, by dlsym */
typedef struct _object PyObject;
typedef ptrdiff_t Py_ssize_t;

static struct {
    int (*IsInitialized)(void);
    void (*InitializeEx)(int);
    void (*SetPythonHome)(const wchar_t *);
    wchar_t *(*DecodeLocale)(const char *, size_t *);
    void *(*SaveThread)(void);
    int (*GILState_Ensure)(void);
    void (*GILState_Release)(int);
    const char *(*GetVersion)(void);
    PyObject *(*ImportModule)(const char *);
    PyObject *(*GetAttrString)(PyObject *, const char *);
    PyObject *(*CallObject)(PyObject *, PyObject *, PyObject *);
    PyObject *(*CallMethodObjArgs)(PyObject *, PyObject *, ...);
    PyObject *(*TupleNew)(Py_ssize_t);
    PyObject *(*DictNew)(void);
    int (*DictSetItemString)(PyObject *, const char *, PyObject *);
    PyObject *(*UnicodeFromString)(const char *);
    const char *(*UnicodeAsUTF8)(PyObject *);
    PyObject *(*LongFromLong)(long);
    long (*LongAsLong)(PyObject *);
    PyObject *(*FloatFromDouble)(double);
    double (*FloatAsDouble)(PyObject *);
    PyObject *(*BoolFromLong)(long);
    PyObject *(*ListNew)(Py_ssize_t);
    int (*ListSetItem)(PyObject *, Py_ssize_t, PyObject *);
    PyObject *(*ListGetItem)(PyObject *, Py_ssize_t);
    Py_ssize_t (*ListSize)(PyObject *);
    int (*ListInsert)(PyObject *, Py_ssize_t, PyObject *);
    int (*ListAppend)(PyObject *, PyObject *);
    int (*ListSetSlice)(PyObject *, Py_ssize_t, Py_ssize_t, PyObject *);
    PyObject *(*SequenceList)(PyObject *);
    int (*IsTrue)(PyObject *);
    PyObject *(*ErrOccurred)(void);
    void (*ErrFetch)(PyObject **, PyObject **, PyObject **);
    void (*ErrNormalize)(PyObject **, PyObject **, PyObject **);
    void (*ErrClear)(void);
    PyObject *(*Str)(PyObject *);
    void (*IncRef)(PyObject *);
    void (*DecRef)(PyObject *);
    PyObject *(*SysGetObject)(const char *);
    PyObject *(*BytesFromStringAndSize)(const char *, Py_ssize_t);
    int (*BytesAsStringAndSize)(PyObject *, char **, Py_ssize_t *);
    PyObject *None;
} py;

static pthread_mutex_t start_lock = PTHREAD_MUTEX_INITIALIZER;
static int python_ready = 0;      /* the API is bound and an interpreter runs */
static char start_problem[4096];  /* why Python could not be started (kept: every later instance says it) */

/* the logger gets the text as its format string with every '%' doubled: hosts that print the message
   without formatting it (many do) show it as written, and hosts that format it get the same text */
static void log_text(const fmi2CallbackFunctions *cb, fmi2String name, fmi2Status status, fmi2String category,
                     const char *text) {
    char escaped[16384];
    size_t k = 0;
    for (const char *p = text; *p && k + 2 < sizeof escaped; ++p) {
        if (*p == '%')
            escaped[k++] = '%';
        escaped[k++] = *p;
    }
    escaped[k] = '\0';
    cb->logger(cb->componentEnvironment, name ? name : "", status, category, escaped);
}

/* ----------------------------------------------------------------- small helpers */
static void say(const fmi2CallbackFunctions *cb, int logging_on, fmi2String name, fmi2Status status,
                fmi2String category, const char *fmt, ...) {
    char text[8192];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    if (logging_on && cb != NULL && cb->logger != NULL)
        log_text(cb, name, status, category, text);
    if (status >= fmi2Error)  /* hosts often leave logging off: an error must be seen somewhere */
        fprintf(stderr, "%s: %s\n", name ? name : "dtcosim FMU", text);
}

static int is_file(const char *path) {
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

/* resources/python.txt: "key=value" lines (libpython, home, version, path (repeated)) */
typedef struct {
    char libpython[1024];
    char home[1024];
    char version[32];
    char paths[16][1024];
    int n_paths;
} Recorded;

static void read_recorded(const char *resources, Recorded *rec) {
    char file[2048], line[1200];
    memset(rec, 0, sizeof *rec);
    snprintf(file, sizeof file, "%s/python.txt", resources);
    FILE *fh = fopen(file, "r");
    if (fh == NULL)
        return;
    while (fgets(line, sizeof line, fh) != NULL) {
        line[strcspn(line, "\r\n")] = '\0';
        char *eq = strchr(line, '=');
        if (eq == NULL)
            continue;
        *eq = '\0';
        const char *key = line, *value = eq + 1;
        if (strcmp(key, "libpython") == 0)
            snprintf(rec->libpython, sizeof rec->libpython, "%s", value);
        else if (strcmp(key, "home") == 0)
            snprintf(rec->home, sizeof rec->home, "%s", value);
        else if (strcmp(key, "version") == 0)
            snprintf(rec->version, sizeof rec->version, "%s", value);
        else if (strcmp(key, "path") == 0 && rec->n_paths < 16)
            snprintf(rec->paths[rec->n_paths++], sizeof rec->paths[0], "%s", value);
    }
    fclose(fh);
}

#define BIND(field, symbol)                                                          \
    do {                                                                             \
        *(void **)(&py.field) = dlsym(lib, symbol);                                  \
        if (py.field == NULL) {                                                      \
            snprintf(start_problem, sizeof start_problem,                            \
                     "%s has no %s: not a CPython 3 library", where, symbol);        \
            return 0;                                                                \
        }                                                                            \
    } while (0)

static int bind_api(void *lib, const char *where) {
    BIND(IsInitialized, "Py_IsInitialized");
    BIND(InitializeEx, "Py_InitializeEx");
    BIND(SetPythonHome, "Py_SetPythonHome");
    BIND(DecodeLocale, "Py_DecodeLocale");
    BIND(SaveThread, "PyEval_SaveThread");
    BIND(GILState_Ensure, "PyGILState_Ensure");
    BIND(GILState_Release, "PyGILState_Release");
    BIND(GetVersion, "Py_GetVersion");
    BIND(ImportModule, "PyImport_ImportModule");
    BIND(GetAttrString, "PyObject_GetAttrString");
    BIND(CallObject, "PyObject_Call");
    BIND(CallMethodObjArgs, "PyObject_CallMethodObjArgs");
    BIND(TupleNew, "PyTuple_New");
    BIND(DictNew, "PyDict_New");
    BIND(DictSetItemString, "PyDict_SetItemString");
    BIND(UnicodeFromString, "PyUnicode_FromString");
    BIND(UnicodeAsUTF8, "PyUnicode_AsUTF8");
    BIND(LongFromLong, "PyLong_FromLong");
    BIND(LongAsLong, "PyLong_AsLong");
    BIND(FloatFromDouble, "PyFloat_FromDouble");
    BIND(FloatAsDouble, "PyFloat_AsDouble");
    BIND(BoolFromLong, "PyBool_FromLong");
    BIND(ListNew, "PyList_New");
    BIND(ListSetItem, "PyList_SetItem");
    BIND(ListGetItem, "PyList_GetItem");
    BIND(ListSize, "PyList_Size");
    BIND(ListInsert, "PyList_Insert");
    BIND(ListAppend, "PyList_Append");
    BIND(ListSetSlice, "PyList_SetSlice");
    BIND(SequenceList, "PySequence_List");
    BIND(IsTrue, "PyObject_IsTrue");
    BIND(ErrOccurred, "PyErr_Occurred");
    BIND(ErrFetch, "PyErr_Fetch");
    BIND(ErrNormalize, "PyErr_NormalizeException");
    BIND(ErrClear, "PyErr_Clear");
    BIND(Str, "PyObject_Str");
    BIND(IncRef, "Py_IncRef");
    BIND(DecRef, "Py_DecRef");
    BIND(SysGetObject, "PySys_GetObject");
    BIND(BytesFromStringAndSize, "PyBytes_FromStringAndSize");
    BIND(BytesAsStringAndSize, "PyBytes_AsStringAndSize");
    BIND(None, "_Py_NoneStruct");
    return 1;
}

/* prepend (front) or append a folder to sys.path; the GIL is held */
static void add_path(const char *folder, int front) {
    PyObject *path = py.SysGetObject("path"); /* borrowed */
    PyObject *s = py.UnicodeFromString(folder);
    if (path != NULL && s != NULL) {
        if (front)
            py.ListInsert(path, 0, s);
        else
            py.ListAppend(path, s);
    }
    if (s != NULL)
        py.DecRef(s);
}

/* start (or join) Python once per process; 1 when ready, else 0 with start_problem set */
static int start_python(const char *resources) {
    pthread_mutex_lock(&start_lock);
    if (python_ready || start_problem[0] != '\0') {
        int ready = python_ready;
        pthread_mutex_unlock(&start_lock);
        return ready;
    }
    /* 1. a Python already running in this process (a Python host: its symbols are global) */
    void *self = dlopen(NULL, RTLD_NOW);
    int (*running)(void) = self ? (int (*)(void))dlsym(self, "Py_IsInitialized") : NULL;
    if (running != NULL && running()) {
        python_ready = bind_api(self, "the host process");
        pthread_mutex_unlock(&start_lock);
        return python_ready;
    }
    /* 2. load libpython with global symbols */
    Recorded rec;
    read_recorded(resources, &rec);
    char tried[2048] = "";
    const char *env_lib = getenv("DTCOSIM_FMU_LIBPYTHON");
    char names[4][1100];
    int n = 0;
    if (env_lib != NULL && env_lib[0] != '\0')
        snprintf(names[n++], sizeof names[0], "%s", env_lib);
    if (rec.libpython[0] != '\0')
        snprintf(names[n++], sizeof names[0], "%s", rec.libpython);
    if (rec.version[0] != '\0') {
        snprintf(names[n++], sizeof names[0], "libpython%s.so.1.0", rec.version);
        snprintf(names[n++], sizeof names[0], "libpython%s.so", rec.version);
    }
    void *lib = NULL;
    const char *found = NULL;
    for (int i = 0; i < n && lib == NULL; ++i) {
        lib = dlopen(names[i], RTLD_NOW | RTLD_GLOBAL);
        if (lib != NULL)
            found = names[i];
        else {
            size_t used = strlen(tried);
            snprintf(tried + used, sizeof tried - used, "%s%s", used ? ", " : "", names[i]);
        }
    }
    if (lib == NULL) {
        snprintf(start_problem, sizeof start_problem,
                 "no Python %s found for this FMU: tried %s (the Python it was built with, recorded in "
                 "resources/python.txt, is not on this machine). Set DTCOSIM_FMU_LIBPYTHON to a "
                 "libpython%s.so, DTCOSIM_FMU_PYTHONHOME to its installation and DTCOSIM_FMU_PYTHONPATH "
                 "to folders holding numpy and scipy",
                 rec.version[0] ? rec.version : "3", n ? tried : "nothing (no resources/python.txt)",
                 rec.version[0] ? rec.version : "3.X");
        pthread_mutex_unlock(&start_lock);
        return 0;
    }
    if (!bind_api(lib, found)) {
        pthread_mutex_unlock(&start_lock);
        return 0;
    }
    if (!py.IsInitialized()) {
        const char *env_home = getenv("DTCOSIM_FMU_PYTHONHOME");
        const char *home = (env_home != NULL && env_home[0] != '\0') ? env_home : rec.home;
        if (home[0] != '\0') {
            char os_py[1200];
            snprintf(os_py, sizeof os_py, "%s/lib/python%s/os.py", home, rec.version);
            if (rec.version[0] != '\0' && !is_file(os_py)) {
                snprintf(start_problem, sizeof start_problem,
                         "the Python home %s has no standard library (%s is missing): set "
                         "DTCOSIM_FMU_PYTHONHOME to the installation of %s",
                         home, os_py, found);
                pthread_mutex_unlock(&start_lock);
                return 0;
            }
            static wchar_t *whome = NULL; /* Py_SetPythonHome keeps the pointer */
            whome = py.DecodeLocale(home, NULL);
            if (whome != NULL)
                py.SetPythonHome(whome);
        }
        py.InitializeEx(0); /* no signal handlers: the host owns SIGINT */
        const char *env_path = getenv("DTCOSIM_FMU_PYTHONPATH");
        if (env_path != NULL && env_path[0] != '\0') {
            char buf[8192];
            snprintf(buf, sizeof buf, "%s", env_path);
            int k = 0;
            for (char *p = strtok(buf, ":"); p != NULL; p = strtok(NULL, ":"))
                if (*p) {
                    PyObject *path = py.SysGetObject("path");
                    PyObject *s = py.UnicodeFromString(p);
                    if (path && s)
                        py.ListInsert(path, k++, s);
                    if (s)
                        py.DecRef(s);
                }
        }
        for (int i = 0; i < rec.n_paths; ++i)
            add_path(rec.paths[i], 0);
        py.SaveThread(); /* release the GIL: every call takes it with PyGILState_Ensure */
    }
    python_ready = 1;
    pthread_mutex_unlock(&start_lock);
    return 1;
}

/* ----------------------------------------------------------------- the instance */
typedef struct {
    PyObject *slave;     /* the Python slave instance */
    PyObject *log_queue; /* its log list */
    char *name;
    char *resources;
    char *module;
    char *class_name;
    fmi2CallbackFunctions cb;
    int logging_on;
    double step_start; /* t of the last fmi2DoStep: fmi2LastSuccessfulTime after a discard */
    double step_end;
    int discarded;
} Instance;

/* forward the slave's log queue; the GIL is held */
static void flush_log(Instance *c) {
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
static void report_exception(Instance *c, const char *what) {
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
static PyObject *call(Instance *c, const char *method, int nargs, PyObject **args) {
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

static fmi2Status simple_call(fmi2Component comp, const char *method, int nargs, PyObject **args) {
    Instance *c = (Instance *)comp;
    int g = py.GILState_Ensure();
    PyObject *r = call(c, method, nargs, args);
    fmi2Status s = r ? fmi2OK : fmi2Error;
    if (r) py.DecRef(r);
    py.GILState_Release(g);
    return s;
}

static PyObject *vr_list(const fmi2ValueReference vr[], size_t n) {
    PyObject *l = py.ListNew((Py_ssize_t)n);
    for (size_t i = 0; i < n; ++i)
        py.ListSetItem(l, (Py_ssize_t)i, py.LongFromLong((long)vr[i]));
    return l;
}

static char *copy_text(const char *s) {
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
        say(functions, loggingOn, instanceName, fmi2Error, "logStatusError", "cannot start Python: %s", start_problem);
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
