/* Finding, loading and starting Python for the dtcosim FMU binary (what dtcosim_fmi2.c's comment describes). */
#include "dtcosim_fmu.h"

struct PythonApi py;

static pthread_mutex_t start_lock = PTHREAD_MUTEX_INITIALIZER;
static int python_ready = 0;      /* the API is bound and an interpreter runs */
static char start_problem[4096];  /* why Python could not be started (kept: every later instance says it) */

/* the logger gets the text as its format string with every '%' doubled: hosts that print the message
   without formatting it (many do) show it as written, and hosts that format it get the same text */
void log_text(const fmi2CallbackFunctions *cb, fmi2String name, fmi2Status status, fmi2String category,
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
void say(const fmi2CallbackFunctions *cb, int logging_on, fmi2String name, fmi2Status status,
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
void add_path(const char *folder, int front) {
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
int start_python(const char *resources) {
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


const char *python_start_problem(void) { return start_problem; }
