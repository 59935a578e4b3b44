/* A careless FMI 2.0 co-simulation host with no Python in it: random call sequences from a seed,
 * legal and not, each checked against the standard's state machine (FMI 2.0 section 4.2.4):
 * a call the standard does not allow in the instance's state, a non-positive, non-finite or
 * non-contiguous step, a get of an unknown value reference or through a NULL array, and an
 * instantiation with a wrong GUID or resource location must fail (fmi2Error, or NULL) and change
 * nothing; every legal call must return fmi2OK. The host must never crash or be exited.
 *
 *   fuzz_host DIR MODEL_ID GUID [--seed S (1)] [--calls N (300)] [--input VR VALUE] [--output VR]
 *             [--cycles K]
 *   --input: a Real input (or tunable parameter) to set, with a value the model takes
 *   --output: a Real output to get
 *   --cycles K: instead, K instantiate/free cycles; prints the resident memory (kB) and the open
 *               file descriptors after the first tenth and at the end
 * Output: "MISMATCH <call k> <what> in <state>: status <got>, expected <want>" for every call
 * that broke the rule, then "DONE calls=<n> refused=<n> mismatches=<n>". Exit 0 when none. */
#define _GNU_SOURCE
#include <dirent.h>
#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status, fmi2String category,
                   fmi2String message, ...) {
    (void)env; (void)instance; (void)status; (void)category; (void)message;  /* quiet: thousands of refusals */
}

enum { INSTANTIATED = 1, INIT = 2, STEP = 4, FAILED = 8, TERMINATED = 16 };
static const char *name_of(int s) {
    switch (s) {
    case INSTANTIATED: return "instantiated";
    case INIT: return "initializationMode";
    case STEP: return "stepComplete";
    case FAILED: return "stepFailed";
    default: return "terminated";
    }
}
/* the standard's table, for the states this host can reach with good values */
#define ALL (INSTANTIATED | INIT | STEP | FAILED | TERMINATED)
#define MASK_GET (INIT | STEP | FAILED | TERMINATED)
#define MASK_SET (INSTANTIATED | INIT | STEP)

static unsigned long long rng;
static unsigned next_random(void) {  /* xorshift64*: the same sequence for a seed everywhere */
    rng ^= rng >> 12; rng ^= rng << 25; rng ^= rng >> 27;
    return (unsigned)((rng * 2685821657736338717ULL) >> 32);
}

static long rss_kb(void) {
    FILE *f = fopen("/proc/self/statm", "r");
    long pages = 0, resident = 0;
    if (f) {
        if (fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
        fclose(f);
    }
    return resident * 4;
}

static int open_fds(void) {
    DIR *d = opendir("/proc/self/fd");
    int n = 0;
    if (!d) return -1;
    while (readdir(d)) n++;
    closedir(d);
    return n - 3;  /* ., .. and the directory itself */
}

#define LOAD(name) name##TYPE *name = (name##TYPE *)dlsym(lib, #name); \
    if (!name) { printf("missing symbol %s\n", #name); return 3; }

int main(int argc, char **argv) {
    if (argc < 4) { fprintf(stderr, "usage: fuzz_host DIR MODEL_ID GUID [options]\n"); return 2; }
    const char *dir = argv[1], *model = argv[2], *guid = argv[3];
    unsigned long long seed = 1;
    int calls = 300, cycles = 0, has_input = 0, has_output = 0;
    unsigned in_vr = 0, out_vr = 0;
    double in_value = 0.0;
    for (int i = 4; i < argc; i++) {
        if (!strcmp(argv[i], "--seed") && i + 1 < argc) seed = strtoull(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "--calls") && i + 1 < argc) calls = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--cycles") && i + 1 < argc) cycles = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--input") && i + 2 < argc) {
            in_vr = (unsigned)atoi(argv[++i]); in_value = atof(argv[++i]); has_input = 1;
        } else if (!strcmp(argv[i], "--output") && i + 1 < argc) { out_vr = (unsigned)atoi(argv[++i]); has_output = 1; }
        else { fprintf(stderr, "unknown option %s\n", argv[i]); return 2; }
    }
    rng = seed * 0x9E3779B97F4A7C15ULL + 1;
    char path[4096], uri[4200], bad_uri[4300];
    snprintf(path, sizeof path, "%s/binaries/linux64/%s.so", dir, model);
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) { printf("dlopen failed: %s\n", dlerror()); return 3; }
    LOAD(fmi2Instantiate) LOAD(fmi2FreeInstance) LOAD(fmi2SetupExperiment) LOAD(fmi2EnterInitializationMode)
    LOAD(fmi2ExitInitializationMode) LOAD(fmi2DoStep) LOAD(fmi2Terminate) LOAD(fmi2Reset) LOAD(fmi2GetReal)
    LOAD(fmi2SetReal) LOAD(fmi2GetFMUstate) LOAD(fmi2SetFMUstate) LOAD(fmi2FreeFMUstate)
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    snprintf(uri, sizeof uri, "file://%s/resources", dir);
    snprintf(bad_uri, sizeof bad_uri, "file://%s/no-such-resources", dir);

    if (cycles > 0) {
        long rss_start = 0;
        int fds_start = 0;
        for (int k = 0; k < cycles; k++) {
            fmi2Component c = fmi2Instantiate("cycle", fmi2CoSimulation, guid, uri, &cb, fmi2False, fmi2False);
            if (!c) { printf("fmi2Instantiate NULL at cycle %d\n", k); return 3; }
            fmi2FreeInstance(c);
            if (k + 1 == (cycles + 9) / 10) { rss_start = rss_kb(); fds_start = open_fds(); }
        }
        printf("CYCLES %d rss_kb %ld %ld fds %d %d\n", cycles, rss_start, rss_kb(), fds_start, open_fds());
        return 0;
    }

    fmi2Component c = fmi2Instantiate("fuzz", fmi2CoSimulation, guid, uri, &cb, fmi2False, fmi2False);
    if (!c) { printf("fmi2Instantiate NULL\n"); return 3; }
    int state = INSTANTIATED, mismatches = 0, refused = 0, have_saved = 0, saved_state = 0;
    double t = 0.0, h = 0.015, saved_t = 0.0;
    fmi2FMUstate saved = NULL;
    for (int k = 0; k < calls; k++) {
        int pick = (int)(next_random() % 20), legal = 1, next = state;
        const char *what = "";
        fmi2Status s = fmi2OK;
        double v = 0.0;
        fmi2ValueReference unknown = 99999999;
        switch (pick) {
        case 0: what = "fmi2SetupExperiment"; legal = state == INSTANTIATED;
            s = fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0); if (legal) t = 0.0; break;
        case 1: what = "fmi2EnterInitializationMode"; legal = state == INSTANTIATED; next = INIT;
            s = fmi2EnterInitializationMode(c); break;
        case 2: what = "fmi2ExitInitializationMode"; legal = state == INIT; next = STEP;
            s = fmi2ExitInitializationMode(c); break;
        case 3: case 4: case 5: case 6: what = "fmi2DoStep"; legal = state == STEP;
            s = fmi2DoStep(c, t, h, fmi2True); if (legal) t += h; break;
        case 7: what = "fmi2DoStep (step size 0, negative or NaN)"; legal = 0;
            s = fmi2DoStep(c, t, (const double[]){0.0, -h, NAN}[next_random() % 3], fmi2True); break;
        case 8: what = "fmi2DoStep (not where the last step ended)"; legal = 0;
            s = fmi2DoStep(c, t + 10 * h, h, fmi2True); break;
        case 9: what = "fmi2Terminate"; legal = (state & (STEP | FAILED)) != 0; next = TERMINATED;
            s = fmi2Terminate(c); break;
        case 10: what = "fmi2Reset"; next = INSTANTIATED; s = fmi2Reset(c); t = 0.0; break;
        case 11: case 12: what = "fmi2GetReal"; legal = has_output && (state & MASK_GET);
            if (!has_output) { k--; continue; }
            s = fmi2GetReal(c, &out_vr, 1, &v); break;
        case 13: what = "fmi2GetReal (unknown value reference)"; legal = 0;
            s = fmi2GetReal(c, &unknown, 1, &v); break;
        case 14: what = "fmi2GetReal (NULL value array)"; legal = 0;
            s = fmi2GetReal(c, &out_vr, 1, NULL); break;
        case 15: what = "fmi2SetReal"; legal = has_input && (state & MASK_SET);
            if (!has_input) { k--; continue; }
            s = fmi2SetReal(c, &in_vr, 1, &in_value); break;
        case 16: what = "fmi2GetFMUstate"; s = fmi2GetFMUstate(c, &saved);
            if (s == fmi2OK) { have_saved = 1; saved_state = state; saved_t = t; } break;
        case 17: what = "fmi2SetFMUstate"; if (!have_saved) { k--; continue; }
            s = fmi2SetFMUstate(c, saved); next = saved_state; t = saved_t; break;
        case 18: {  /* instantiations the FMU must refuse, then sometimes a fresh instance */
            what = "fmi2Instantiate (wrong GUID or resource location)"; legal = 0;
            int wrong_guid = next_random() % 2;
            fmi2Component bad = fmi2Instantiate("bad", fmi2CoSimulation, wrong_guid ? "{not-this-fmu}" : guid,
                                                wrong_guid ? uri : bad_uri, &cb, fmi2False, fmi2False);
            s = bad ? fmi2OK : fmi2Error;
            if (bad) fmi2FreeInstance(bad);
            break;
        }
        default:
            if (next_random() % 4) { k--; continue; }
            what = "fmi2FreeInstance + fmi2Instantiate";
            if (saved) { fmi2FreeFMUstate(c, &saved); saved = NULL; have_saved = 0; }
            fmi2FreeInstance(c);
            c = fmi2Instantiate("fuzz", fmi2CoSimulation, guid, uri, &cb, fmi2False, fmi2False);
            if (!c) { printf("fmi2Instantiate NULL after a free\n"); return 3; }
            s = fmi2OK; next = INSTANTIATED; t = 0.0;
        }
        fmi2Status want = legal ? fmi2OK : fmi2Error;
        if (s != want) {
            printf("MISMATCH %d %s in %s: status %d, expected %d\n", k, what, name_of(state), (int)s, (int)want);
            mismatches++;
        }
        if (!legal) refused++;
        if (legal && s == fmi2OK) state = next;
    }
    if (saved) fmi2FreeFMUstate(c, &saved);
    fmi2FreeInstance(c);
    printf("DONE calls=%d refused=%d mismatches=%d\n", calls, refused, mismatches);
    fflush(stdout);
    return mismatches ? 3 : 0;
}
