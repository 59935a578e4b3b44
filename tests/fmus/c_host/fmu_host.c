/* A minimal FMI 2.0 co-simulation host with no Python in it: dlopen an extracted FMU's binary,
 * instantiate, set parameters, initialize, step, read outputs, terminate, free, unload, and do
 * it all again. The tests run it on every FMU of the product.
 *
 *   fmu_host DIR MODEL_ID GUID [options]
 *     --set-real VR VALUE   --set-string VR TEXT   --get-real VR   --get-string VR
 *     --steps N (3)         --step H (0.015)       --rounds K (2)   --threads (call from a thread)
 * Output: "LOG <status> <category>: <message>" for every message, "GET <vr> <value>" for every
 * read, "STATUS <call> <status>" for a call that did not return fmi2OK. Exit 0 when every call
 * returned fmi2OK, 3 otherwise. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status, fmi2String category,
                   fmi2String message, ...) {
    (void)env;
    (void)instance;
    char text[8192];
    va_list ap;
    va_start(ap, message);
    vsnprintf(text, sizeof text, message, ap); /* FMI: message is a printf format */
    va_end(ap);
    printf("LOG %d %s: %s\n", (int)status, category ? category : "", text);
    fflush(stdout);
}

#define MAX_OPS 64
typedef struct { char kind; unsigned vr; double real; const char *text; } Op;
static Op ops[MAX_OPS];
static int n_ops = 0, steps = 3, rounds = 2, threads = 0;
static double h = 0.015;
static const char *dir, *model, *guid;
static int failures = 0;

#define LOAD(name) name##TYPE *name = (name##TYPE *)dlsym(lib, #name); \
    if (!name) { printf("missing symbol %s\n", #name); return NULL; }
#define CHECK(call) do { fmi2Status s_ = (call); if (s_ != fmi2OK) { \
    printf("STATUS %s %d\n", #call, (int)s_); fflush(stdout); failures++; } } while (0)

static void *run_round(void *arg) {
    (void)arg;
    char path[4096], uri[4200];
    snprintf(path, sizeof path, "%s/binaries/linux64/%s.so", dir, model);
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) { printf("dlopen failed: %s\n", dlerror()); failures++; return NULL; }
    LOAD(fmi2Instantiate) LOAD(fmi2SetupExperiment) LOAD(fmi2EnterInitializationMode)
    LOAD(fmi2ExitInitializationMode) LOAD(fmi2DoStep) LOAD(fmi2GetReal) LOAD(fmi2SetReal) LOAD(fmi2SetString)
    LOAD(fmi2GetString) LOAD(fmi2Terminate) LOAD(fmi2FreeInstance) LOAD(fmi2SetDebugLogging)
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    snprintf(uri, sizeof uri, "file://%s/resources", dir);
    fmi2Component c = fmi2Instantiate("host", fmi2CoSimulation, guid, uri, &cb, fmi2False, fmi2True);
    if (!c) { printf("STATUS fmi2Instantiate NULL\n"); failures++; dlclose(lib); return NULL; }
    CHECK(fmi2SetDebugLogging(c, fmi2True, 0, NULL));
    CHECK(fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0));
    CHECK(fmi2EnterInitializationMode(c));
    for (int i = 0; i < n_ops; i++) {
        if (ops[i].kind == 'r') CHECK(fmi2SetReal(c, &ops[i].vr, 1, &ops[i].real));
        if (ops[i].kind == 's') CHECK(fmi2SetString(c, &ops[i].vr, 1, &ops[i].text));
    }
    CHECK(fmi2ExitInitializationMode(c));
    for (int k = 0; k < steps; k++) CHECK(fmi2DoStep(c, k * h, h, fmi2True));
    for (int i = 0; i < n_ops; i++) {
        if (ops[i].kind == 'g') {
            double v = 0.0;
            CHECK(fmi2GetReal(c, &ops[i].vr, 1, &v));
            printf("GET %u %.17g\n", ops[i].vr, v);
        }
        if (ops[i].kind == 't') {
            fmi2String v = NULL;
            CHECK(fmi2GetString(c, &ops[i].vr, 1, &v));
            printf("GET %u %s\n", ops[i].vr, v ? v : "(null)");
        }
    }
    CHECK(fmi2Terminate(c));
    fmi2FreeInstance(c);
    if (dlclose(lib) != 0) { printf("dlclose failed\n"); failures++; }
    fflush(stdout);
    return NULL;
}

int main(int argc, char **argv) {
    if (argc < 4) { fprintf(stderr, "usage: fmu_host DIR MODEL_ID GUID [options]\n"); return 2; }
    dir = argv[1]; model = argv[2]; guid = argv[3];
    for (int i = 4; i < argc; i++) {
        if (!strcmp(argv[i], "--set-real") && i + 2 < argc && n_ops < MAX_OPS) {
            ops[n_ops++] = (Op){'r', (unsigned)atoi(argv[i + 1]), atof(argv[i + 2]), NULL}; i += 2;
        } else if (!strcmp(argv[i], "--set-string") && i + 2 < argc && n_ops < MAX_OPS) {
            ops[n_ops++] = (Op){'s', (unsigned)atoi(argv[i + 1]), 0.0, argv[i + 2]}; i += 2;
        } else if (!strcmp(argv[i], "--get-real") && i + 1 < argc && n_ops < MAX_OPS) {
            ops[n_ops++] = (Op){'g', (unsigned)atoi(argv[i + 1]), 0.0, NULL}; i += 1;
        } else if (!strcmp(argv[i], "--get-string") && i + 1 < argc && n_ops < MAX_OPS) {
            ops[n_ops++] = (Op){'t', (unsigned)atoi(argv[i + 1]), 0.0, NULL}; i += 1;
        } else if (!strcmp(argv[i], "--steps") && i + 1 < argc) { steps = atoi(argv[++i]);
        } else if (!strcmp(argv[i], "--step") && i + 1 < argc) { h = atof(argv[++i]);
        } else if (!strcmp(argv[i], "--rounds") && i + 1 < argc) { rounds = atoi(argv[++i]);
        } else if (!strcmp(argv[i], "--threads")) { threads = 1;
        } else { fprintf(stderr, "unknown option %s\n", argv[i]); return 2; }
    }
    for (int r = 0; r < rounds; r++) {
        printf("ROUND %d\n", r + 1);
        if (threads) {
            pthread_t t;
            pthread_create(&t, NULL, run_round, NULL);
            pthread_join(t, NULL);
        } else {
            run_round(NULL);
        }
    }
    printf("DONE failures=%d\n", failures);
    return failures ? 3 : 0;
}
