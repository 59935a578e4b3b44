/* An FMI 2.0 co-simulation host that runs many FMU instances from several threads at once, with no
 * Python in it: a thread pool (pthreads) takes the jobs of a job file one by one; each job loads
 * an extracted FMU's binary (every job its own dlopen handle of the same file), instantiates,
 * initializes, steps, reads the listed Real outputs after every step, terminates and frees. The
 * same FMU may be listed several times (instantiated twice at once). Results are printed in job
 * order after every thread finished, so a run with --threads 1 is the reference for a run with
 * --threads 8.
 *
 *   threaded_host JOBFILE [--threads N (8)] [--steps N (3)] [--step H (0.015)]
 *   JOBFILE: one job a line, "DIR MODEL_ID GUID VR,VR,... [IN_VR IN_VALUE]" (VR list may be "-":
 *   no outputs; IN_VR: a Real input set to IN_VALUE before every step)
 * Output: "JOB <k> <name> <value> <value> ..." (%.17g, every output after every step), a
 * "FAIL <k> <call> <status>" line for a call that did not return fmi2OK, "LOG <k> <status>
 * <message>" for messages of status warning and worse. Exit 0 when every call returned fmi2OK. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

#define MAX_JOBS 512
#define MAX_OUT 64
#define MAX_TEXT 65536

typedef struct {
    char dir[1024], model[256], guid[256];
    unsigned vr[MAX_OUT];
    int n_vr;
    unsigned in_vr;
    double in_value;
    int has_input;
    char *text; /* what the job prints, written by its thread */
    size_t used;
    int failures;
} Job;

static Job jobs[MAX_JOBS];
static int n_jobs = 0, steps = 3;
static double h = 0.015;
static int next_job = 0;
static pthread_mutex_t queue = PTHREAD_MUTEX_INITIALIZER;

static void out(Job *job, const char *fmt, ...) {
    if (!job->text) job->text = calloc(MAX_TEXT, 1);
    if (!job->text || job->used + 1 >= MAX_TEXT) return;
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(job->text + job->used, MAX_TEXT - job->used, fmt, ap);
    va_end(ap);
    if (n > 0) job->used += (size_t)n < MAX_TEXT - job->used ? (size_t)n : MAX_TEXT - job->used - 1;
}

static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status, fmi2String category,
                   fmi2String message, ...) {
    (void)instance;
    (void)category;
    if (status < fmi2Warning) return;
    Job *job = (Job *)env;
    char text[2048];
    va_list ap;
    va_start(ap, message);
    vsnprintf(text, sizeof text, message, ap);
    va_end(ap);
    out(job, "LOG %d %d %s\n", (int)(job - jobs), (int)status, text);
}

#define LOAD(name) name##TYPE *name = (name##TYPE *)dlsym(lib, #name); \
    if (!name) { out(job, "FAIL %d missing-symbol %s\n", k, #name); job->failures++; dlclose(lib); return; }
#define CHECK(call) do { fmi2Status s_ = (call); if (s_ != fmi2OK) { \
    out(job, "FAIL %d %s %d\n", k, #call, (int)s_); job->failures++; } } while (0)

static void run_job(int k) {
    Job *job = &jobs[k];
    char path[2048], uri[2100], name[64];
    snprintf(path, sizeof path, "%s/binaries/linux64/%s.so", job->dir, job->model);
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) { out(job, "FAIL %d dlopen %s\n", k, dlerror()); job->failures++; return; }
    LOAD(fmi2Instantiate) LOAD(fmi2SetupExperiment) LOAD(fmi2EnterInitializationMode)
    LOAD(fmi2ExitInitializationMode) LOAD(fmi2DoStep) LOAD(fmi2GetReal) LOAD(fmi2SetReal) LOAD(fmi2Terminate)
    LOAD(fmi2FreeInstance)
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, job};
    snprintf(uri, sizeof uri, "file://%s/resources", job->dir);
    snprintf(name, sizeof name, "job%d", k);
    fmi2Component c = fmi2Instantiate(name, fmi2CoSimulation, job->guid, uri, &cb, fmi2False, fmi2False);
    if (!c) { out(job, "FAIL %d fmi2Instantiate NULL\n", k); job->failures++; dlclose(lib); return; }
    CHECK(fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0));
    CHECK(fmi2EnterInitializationMode(c));
    CHECK(fmi2ExitInitializationMode(c));
    out(job, "JOB %d %s", k, job->model);
    double values[MAX_OUT];
    for (int i = 0; i < steps; i++) {
        if (job->has_input) CHECK(fmi2SetReal(c, &job->in_vr, 1, &job->in_value));
        CHECK(fmi2DoStep(c, i * h, h, fmi2True));
        if (job->n_vr) {
            CHECK(fmi2GetReal(c, job->vr, (size_t)job->n_vr, values));
            for (int j = 0; j < job->n_vr; j++) out(job, " %.17g", values[j]);
        }
    }
    out(job, "\n");
    CHECK(fmi2Terminate(c));
    fmi2FreeInstance(c);
    dlclose(lib);
}

static void *worker(void *arg) {
    (void)arg;
    for (;;) {
        pthread_mutex_lock(&queue);
        int k = next_job < n_jobs ? next_job++ : -1;
        pthread_mutex_unlock(&queue);
        if (k < 0) return NULL;
        run_job(k);
    }
}

int main(int argc, char **argv) {
    if (argc < 2) { fprintf(stderr, "usage: threaded_host JOBFILE [--threads N] [--steps N] [--step H]\n"); return 2; }
    int threads = 8;
    for (int i = 2; i < argc; i++) {
        if (!strcmp(argv[i], "--threads") && i + 1 < argc) threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--steps") && i + 1 < argc) steps = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--step") && i + 1 < argc) h = atof(argv[++i]);
        else { fprintf(stderr, "unknown option %s\n", argv[i]); return 2; }
    }
    FILE *f = fopen(argv[1], "r");
    if (!f) { fprintf(stderr, "cannot read %s\n", argv[1]); return 2; }
    char line[8192], vrs[4096];
    while (n_jobs < MAX_JOBS && fgets(line, sizeof line, f)) {
        Job *job = &jobs[n_jobs];
        int fields = sscanf(line, "%1023s %255s %255s %4095s %u %lf", job->dir, job->model, job->guid, vrs,
                            &job->in_vr, &job->in_value);
        if (fields != 4 && fields != 6) continue;
        job->has_input = fields == 6;
        if (strcmp(vrs, "-") != 0)
            for (char *p = strtok(vrs, ","); p && job->n_vr < MAX_OUT; p = strtok(NULL, ","))
                job->vr[job->n_vr++] = (unsigned)strtoul(p, NULL, 10);
        n_jobs++;
    }
    fclose(f);
    if (threads < 1) threads = 1;
    pthread_t pool[64];
    if (threads > 64) threads = 64;
    for (int t = 0; t < threads; t++) pthread_create(&pool[t], NULL, worker, NULL);
    for (int t = 0; t < threads; t++) pthread_join(pool[t], NULL);
    int failures = 0;
    for (int k = 0; k < n_jobs; k++) {
        if (jobs[k].text) fputs(jobs[k].text, stdout);
        failures += jobs[k].failures;
    }
    printf("DONE jobs=%d threads=%d failures=%d\n", n_jobs, threads, failures);
    return failures ? 3 : 0;
}
