/*
 * Minimal FMI 2.0 co-simulation host in C: runs the dtcosim Gearbox FMU alone with a
 * constant-speed, kinematically consistent rotor and generator motion and prints the
 * shaft-3 torque. It shows what a C host (Simulink S-function, custom master) needs
 * for a pythonfmu FMU: libpython loaded with global symbols (here: LD_PRELOAD, or
 * dlopen(libpython, RTLD_NOW | RTLD_GLOBAL) before the FMU) and a Python whose
 * sys.path reaches numpy and scipy (e.g. PYTHONPATH=<venv>/lib/python3.X/site-packages).
 *
 * Build: cc -o c_host c_host.c -ldl
 * Usage: c_host BINARY.so RESOURCE_URI GUID STEPS VR_OMEGA_ROTOR VR_PHI_ROTOR VR_OMEGA_GEN VR_PHI_GEN VR_SHAFT_TORQUE
 */
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

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
    fprintf(stderr, "[%s status %d] %s\n", instance, (int)status, message);
}

typedef fmi2Component (*Instantiate)(fmi2String, fmi2Type, fmi2String, fmi2String, const fmi2CallbackFunctions *,
                                     fmi2Boolean, fmi2Boolean);
typedef fmi2Status (*SetupExperiment)(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real, fmi2Boolean, fmi2Real);
typedef fmi2Status (*ComponentCall)(fmi2Component);
typedef fmi2Status (*SetReal)(fmi2Component, const fmi2ValueReference *, size_t, const fmi2Real *);
typedef fmi2Status (*GetReal)(fmi2Component, const fmi2ValueReference *, size_t, fmi2Real *);
typedef fmi2Status (*DoStep)(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean);
typedef void (*FreeInstance)(fmi2Component);

#define LOAD(type, name)                                                   \
    type name = (type)dlsym(lib, #name);                                   \
    if (!name) {                                                           \
        fprintf(stderr, "missing %s\n", #name);                           \
        return 2;                                                          \
    }

#define CHECK(call)                                                        \
    if ((call) > fmi2Warning) {                                            \
        fprintf(stderr, "%s failed\n", #call);                             \
        return 3;                                                          \
    }

int main(int argc, char **argv) {
    if (argc != 10) {
        fprintf(stderr, "usage: %s BINARY RESOURCE_URI GUID STEPS VR_OR VR_PR VR_OG VR_PG VR_TORQUE\n", argv[0]);
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

    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    fmi2Component c = fmi2Instantiate("gearbox", fmi2CoSimulation, argv[3], argv[2], &callbacks, 0, 1);
    if (!c) {
        fprintf(stderr, "fmi2Instantiate failed\n");
        return 3;
    }
    int steps = atoi(argv[4]);
    fmi2ValueReference inputs[4] = {(fmi2ValueReference)atoi(argv[5]), (fmi2ValueReference)atoi(argv[6]),
                                    (fmi2ValueReference)atoi(argv[7]), (fmi2ValueReference)atoi(argv[8])};
    fmi2ValueReference torque_vr = (fmi2ValueReference)atoi(argv[9]);
    const double h = 1e-3, omega_rotor = 1.6755160819145563, ratio = 100.0, omega_gen = 0.99 * ratio * omega_rotor;
    double u[4] = {omega_rotor, 0.0, omega_gen, 0.0}, torque = 0.0;
    CHECK(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0))
    CHECK(fmi2EnterInitializationMode(c))
    CHECK(fmi2SetReal(c, inputs, 4, u))
    CHECK(fmi2ExitInitializationMode(c))
    for (int n = 0; n < steps; ++n) {
        double t = n * h;
        u[1] = omega_rotor * t;
        u[3] = omega_gen * t;
        CHECK(fmi2SetReal(c, inputs, 4, u))
        CHECK(fmi2DoStep(c, t, h, 1))
        CHECK(fmi2GetReal(c, &torque_vr, 1, &torque))
    }
    printf("shaft_torque %.17g\n", torque);
    CHECK(fmi2Terminate(c))
    fmi2FreeInstance(c);
    return 0;
}
