/*
 * Minimal FMI 2.0 co-simulation host in C: what a Simulink S-function or a company master does
 * with an FMU, with nothing else in the process (no Python, no preloaded library, no environment).
 *
 *   c_host BINARY.so RESOURCE_URI GUID STEPS VR_OUT [VR_OMEGA_ROTOR VR_PHI_ROTOR VR_OMEGA_GEN VR_PHI_GEN]
 *
 * Instantiates the FMU, initialises it, takes STEPS steps of 1 ms and prints the Real output VR_OUT.
 * With the four Gearbox inputs it drives the Gearbox alone with a constant-speed, kinematically
 * consistent rotor and generator motion (generator at 0.99 x 100 x rotor speed). With
 * INSTANCES=2 in the environment it runs two instances side by side (each must give the same
 * output), and with AGAIN=1 it frees them and instantiates a new one in the same process, which
 * must give the same output again (hosts such as Simulink do both).
 *
 * Build: cc -o c_host c_host.c -ldl
 * Exit status: 0 ok; 1 usage; 2 binary or symbol not loadable; 3 an FMI call failed; 4 instances disagree.
 */
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Boolean;
typedef const char *fmi2String;
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;

typedef struct {
    void (*logger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...);
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status, fmi2String category,
                   fmi2String message, ...) {
    (void)env;
    (void)category;
    char text[8192];
    va_list ap;
    va_start(ap, message);
    vsnprintf(text, sizeof text, message, ap); /* the message is a format string (FMI 2.0, 2.1.5) */
    va_end(ap);
    fprintf(stderr, "[%s status %d] %s\n", instance, (int)status, text);
}

typedef fmi2Component (*Instantiate)(fmi2String, fmi2Type, fmi2String, fmi2String, const fmi2CallbackFunctions *,
                                     fmi2Boolean, fmi2Boolean);
typedef fmi2Status (*SetupExperiment)(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real, fmi2Boolean, fmi2Real);
typedef fmi2Status (*ComponentCall)(fmi2Component);
typedef fmi2Status (*SetReal)(fmi2Component, const fmi2ValueReference *, size_t, const fmi2Real *);
typedef fmi2Status (*GetReal)(fmi2Component, const fmi2ValueReference *, size_t, fmi2Real *);
typedef fmi2Status (*DoStep)(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean);
typedef void (*FreeInstance)(fmi2Component);

static Instantiate fmi2Instantiate;
static SetupExperiment fmi2SetupExperiment;
static ComponentCall fmi2EnterInitializationMode, fmi2ExitInitializationMode, fmi2Terminate;
static SetReal fmi2SetReal;
static GetReal fmi2GetReal;
static DoStep fmi2DoStep;
static FreeInstance fmi2FreeInstance;

#define LOAD(type, name)                                                   \
    name = (type)dlsym(lib, #name);                                        \
    if (!name) {                                                           \
        fprintf(stderr, "missing %s\n", #name);                           \
        return 2;                                                          \
    }

#define CHECK(call)                                                        \
    if ((call) > fmi2Warning) {                                            \
        fprintf(stderr, "%s failed\n", #call);                             \
        return 3;                                                          \
    }

static fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
static const double h = 1e-3, omega_rotor = 1.6755160819145563, ratio = 100.0;

/* n instances run side by side for `steps` steps; out[i] is instance i's output */
static int run(const char *name, const char *uri, const char *guid, int steps, int n, fmi2ValueReference out_vr,
               const fmi2ValueReference *inputs, int n_inputs, double *out) {
    const double omega_gen = 0.99 * ratio * omega_rotor;
    fmi2Component c[4] = {0};
    for (int i = 0; i < n; ++i) {
        char instance[64];
        snprintf(instance, sizeof instance, "%s%d", name, i + 1);
        c[i] = fmi2Instantiate(instance, fmi2CoSimulation, guid, uri, &callbacks, 0, 1);
        if (!c[i]) {
            fprintf(stderr, "fmi2Instantiate failed\n");
            return 3;
        }
    }
    double u[4] = {omega_rotor, 0.0, omega_gen, 0.0};
    for (int i = 0; i < n; ++i) {
        CHECK(fmi2SetupExperiment(c[i], 0, 0.0, 0.0, 0, 0.0))
        CHECK(fmi2EnterInitializationMode(c[i]))
        if (n_inputs == 4)
            CHECK(fmi2SetReal(c[i], inputs, 4, u))
        CHECK(fmi2ExitInitializationMode(c[i]))
    }
    for (int k = 0; k < steps; ++k) {
        double t = k * h;
        u[1] = omega_rotor * t;
        u[3] = omega_gen * t;
        for (int i = 0; i < n; ++i) {
            if (n_inputs == 4)
                CHECK(fmi2SetReal(c[i], inputs, 4, u))
            CHECK(fmi2DoStep(c[i], t, h, 1))
            CHECK(fmi2GetReal(c[i], &out_vr, 1, &out[i]))
        }
    }
    for (int i = 0; i < n; ++i) {
        CHECK(fmi2Terminate(c[i]))
        fmi2FreeInstance(c[i]);
    }
    return 0;
}

int main(int argc, char **argv) {
    if (argc != 6 && argc != 10) {
        fprintf(stderr, "usage: %s BINARY RESOURCE_URI GUID STEPS VR_OUT [VR_OR VR_PR VR_OG VR_PG]\n", argv[0]);
        return 1;
    }
    void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "dlopen: %s\n", dlerror());
        return 2;
    }
    LOAD(Instantiate, fmi2Instantiate)
    LOAD(SetupExperiment, fmi2SetupExperiment)
    LOAD(ComponentCall, fmi2EnterInitializationMode)
    LOAD(ComponentCall, fmi2ExitInitializationMode)
    LOAD(SetReal, fmi2SetReal)
    LOAD(GetReal, fmi2GetReal)
    LOAD(DoStep, fmi2DoStep)
    LOAD(ComponentCall, fmi2Terminate)
    LOAD(FreeInstance, fmi2FreeInstance)

    int steps = atoi(argv[4]);
    fmi2ValueReference out_vr = (fmi2ValueReference)atoi(argv[5]);
    fmi2ValueReference inputs[4];
    int n_inputs = argc == 10 ? 4 : 0;
    for (int i = 0; i < n_inputs; ++i)
        inputs[i] = (fmi2ValueReference)atoi(argv[6 + i]);
    int n = getenv("INSTANCES") ? atoi(getenv("INSTANCES")) : 1;
    if (n < 1 || n > 4)
        n = 1;
    double out[4] = {0};
    int rc = run("fmu", argv[2], argv[3], steps, n, out_vr, inputs, n_inputs, out);
    if (rc)
        return rc;
    for (int i = 1; i < n; ++i)
        if (out[i] != out[0]) {
            fprintf(stderr, "instance %d gives %.17g, instance 1 %.17g\n", i + 1, out[i], out[0]);
            return 4;
        }
    if (getenv("AGAIN") && atoi(getenv("AGAIN"))) {
        double again[4] = {0};
        rc = run("again", argv[2], argv[3], steps, 1, out_vr, inputs, n_inputs, again);
        if (rc)
            return rc;
        if (again[0] != out[0]) {
            fprintf(stderr, "a new instance after freeing gives %.17g, the first %.17g\n", again[0], out[0]);
            return 4;
        }
    }
    printf("output %.17g\n", out[0]);
    return 0;
}
