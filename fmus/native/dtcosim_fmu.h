/* Shared declarations of the dtcosim FMU binary (see dtcosim_fmi2.c for what it is and does). */
#ifndef DTCOSIM_FMU_H
#define DTCOSIM_FMU_H

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

struct PythonApi {
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
};
extern struct PythonApi py;


/* python_runtime.c: find, load and start Python; log through the host */
int start_python(const char *resources);
const char *python_start_problem(void);
void log_text(const fmi2CallbackFunctions *cb, fmi2String name, fmi2Status status, fmi2String category,
              const char *text);
void say(const fmi2CallbackFunctions *cb, int logging_on, fmi2String name, fmi2Status status, fmi2String category,
         const char *fmt, ...);
void add_path(const char *folder, int front);

/* instance.c: one FMU instance and its calls into the Python slave */
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

void flush_log(Instance *c);
void report_exception(Instance *c, const char *what);
PyObject *call(Instance *c, const char *method, int nargs, PyObject **args);
fmi2Status simple_call(fmi2Component comp, const char *method, int nargs, PyObject **args);
PyObject *vr_list(const fmi2ValueReference vr[], size_t n);
char *copy_text(const char *s);

#endif
