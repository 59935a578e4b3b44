/* The part of the runtime both FMI versions share: finding and starting a CPython on the target,
 * loading the model through neighbor_runtime.py, and the calls into the model with their error
 * handling (see neighbor_fmi2.c for the guarantees). Included by neighbor_fmi2.c and
 * neighbor_fmi3.c, each compiled on its own into the FMU binary of its standard: one translation
 * unit per binary, so every function here stays static and nothing but the standard's entry
 * points is exported. */
#if !defined(_WIN32) && !defined(_GNU_SOURCE)
#define _GNU_SOURCE  /* dladdr; the front end defines it before any header */
#endif
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _WIN32
#include <windows.h>
typedef HMODULE lib_handle;
static void *lib_sym(lib_handle h, const char *name) { return (void *)GetProcAddress(h, name); }
static void *process_sym(const char *name) {
    /* a Python already in the host: look in the modules the process has loaded */
    static const char *dlls[] = {"python3.dll", "python313.dll", "python312.dll", "python311.dll", "python310.dll"};
    for (size_t i = 0; i < sizeof dlls / sizeof dlls[0]; i++) {
        HMODULE m = GetModuleHandleA(dlls[i]);
        if (m) {
            void *p = (void *)GetProcAddress(m, name);
            if (p) return p;
        }
    }
    return NULL;
}
#define PATH_SEP '\\'
#else
#include <dlfcn.h>
#include <sys/wait.h>
typedef void *lib_handle;
static void *lib_sym(lib_handle h, const char *name) { return dlsym(h, name); }
static void *process_sym(const char *name) { return dlsym(RTLD_DEFAULT, name); }
#define PATH_SEP '/'
#endif

/* One lock per loaded library around loading its loader: hosts may instantiate from several
 * threads at once (libcosim's thread pool, a Python host's threads; starting Python has a lock of
 * the whole process, see start_runtime).
 * new_instance waits for it with the GIL released, so it never waits on Python. The Python
 * side serializes its own import work across every FMU build (neighbor_runtime.py: _LOCK). */
#ifdef _WIN32
static volatile LONG runtime_lock_word = 0;
static void runtime_lock(void) {
    while (InterlockedCompareExchange(&runtime_lock_word, 1, 0) != 0) Sleep(0);
}
static void runtime_unlock(void) { InterlockedExchange(&runtime_lock_word, 0); }
#else
#include <pthread.h>
static pthread_mutex_t runtime_mutex = PTHREAD_MUTEX_INITIALIZER;
static void runtime_lock(void) { pthread_mutex_lock(&runtime_mutex); }
static void runtime_unlock(void) { pthread_mutex_unlock(&runtime_mutex); }
#endif

/* ---- the Python C API, by pointer ---------------------------------------------------------- */
typedef struct _object PyObject;
typedef ptrdiff_t Py_ssize_t;
#define PY_FILE_INPUT 257 /* Py_file_input */

static struct {
    int (*IsInitialized)(void);
    void (*InitializeEx)(int);
    void *(*EvalSaveThread)(void);
    void (*EvalRestoreThread)(void *);
    int (*GILStateEnsure)(void);
    void (*GILStateRelease)(int);
    PyObject *(*RunString)(const char *, int, PyObject *, PyObject *);
    PyObject *(*DictNew)(void);
    int (*DictSetItemString)(PyObject *, const char *, PyObject *);
    PyObject *(*DictGetItemString)(PyObject *, const char *);
    PyObject *(*EvalGetBuiltins)(void);
    PyObject *(*GetAttrString)(PyObject *, const char *);
    PyObject *(*CallObject)(PyObject *, PyObject *);
    PyObject *(*Str)(PyObject *);
    PyObject *(*TupleNew)(Py_ssize_t);
    int (*TupleSetItem)(PyObject *, Py_ssize_t, PyObject *);
    PyObject *(*TupleGetItem)(PyObject *, Py_ssize_t);
    PyObject *(*ListNew)(Py_ssize_t);
    int (*ListSetItem)(PyObject *, Py_ssize_t, PyObject *);
    PyObject *(*ListGetItem)(PyObject *, Py_ssize_t);
    Py_ssize_t (*ListSize)(PyObject *);
    PyObject *(*LongFromLong)(long);
    PyObject *(*LongFromUnsignedLong)(unsigned long);
    long (*LongAsLong)(PyObject *);
    PyObject *(*FloatFromDouble)(double);
    double (*FloatAsDouble)(PyObject *);
    PyObject *(*BoolFromLong)(long);
    int (*IsTrue)(PyObject *);
    PyObject *(*UnicodeFromString)(const char *);
    const char *(*UnicodeAsUTF8)(PyObject *);
    PyObject *(*ErrOccurred)(void);
    void (*ErrFetch)(PyObject **, PyObject **, PyObject **);
    void (*ErrNormalize)(PyObject **, PyObject **, PyObject **);
    void (*ErrClear)(void);
    void (*IncRef)(PyObject *);
    void (*DecRef)(PyObject *);
    PyObject *(*ImportAddModule)(const char *);
    PyObject *(*ModuleGetDict)(PyObject *);
    void *(*LongAsVoidPtr)(PyObject *);
} py;

static const struct { const char *name; size_t offset; } PY_SYMBOLS[] = {
#define S(field, name) {name, offsetof(__typeof__(py), field)}
    S(IsInitialized, "Py_IsInitialized"), S(InitializeEx, "Py_InitializeEx"),
    S(EvalSaveThread, "PyEval_SaveThread"), S(EvalRestoreThread, "PyEval_RestoreThread"),
    S(GILStateEnsure, "PyGILState_Ensure"),
    S(GILStateRelease, "PyGILState_Release"), S(RunString, "PyRun_String"), S(DictNew, "PyDict_New"),
    S(DictSetItemString, "PyDict_SetItemString"), S(DictGetItemString, "PyDict_GetItemString"),
    S(EvalGetBuiltins, "PyEval_GetBuiltins"), S(GetAttrString, "PyObject_GetAttrString"),
    S(CallObject, "PyObject_CallObject"), S(Str, "PyObject_Str"), S(TupleNew, "PyTuple_New"), S(TupleSetItem, "PyTuple_SetItem"),
    S(TupleGetItem, "PyTuple_GetItem"), S(ListNew, "PyList_New"), S(ListSetItem, "PyList_SetItem"),
    S(ListGetItem, "PyList_GetItem"), S(ListSize, "PyList_Size"), S(LongFromLong, "PyLong_FromLong"),
    S(LongFromUnsignedLong, "PyLong_FromUnsignedLong"), S(LongAsLong, "PyLong_AsLong"),
    S(FloatFromDouble, "PyFloat_FromDouble"), S(FloatAsDouble, "PyFloat_AsDouble"),
    S(BoolFromLong, "PyBool_FromLong"), S(IsTrue, "PyObject_IsTrue"),
    S(UnicodeFromString, "PyUnicode_FromString"), S(UnicodeAsUTF8, "PyUnicode_AsUTF8"),
    S(ErrOccurred, "PyErr_Occurred"), S(ErrFetch, "PyErr_Fetch"), S(ErrNormalize, "PyErr_NormalizeException"),
    S(ErrClear, "PyErr_Clear"), S(IncRef, "Py_IncRef"), S(DecRef, "Py_DecRef"),
    S(ImportAddModule, "PyImport_AddModule"), S(ModuleGetDict, "PyModule_GetDict"),
    S(LongAsVoidPtr, "PyLong_AsVoidPtr"),
#undef S
};

/* ---- one runtime per loaded library ---------------------------------------------------------- */
static int runtime_ready = 0;  /* the API is resolved and an interpreter runs */
static int runtime_embedded = 0;  /* this library started the interpreter */
static char runtime_error[2048];  /* why the runtime could not start (reported per instance) */
static PyObject *loader = NULL;  /* namespace of neighbor_runtime.py */

static int resolve_all(lib_handle handle) {
    for (size_t i = 0; i < sizeof PY_SYMBOLS / sizeof PY_SYMBOLS[0]; i++) {
        void *p = handle ? lib_sym(handle, PY_SYMBOLS[i].name) : process_sym(PY_SYMBOLS[i].name);
        if (!p) {
            snprintf(runtime_error, sizeof runtime_error, "the Python library lacks %s", PY_SYMBOLS[i].name);
            return 0;
        }
        memcpy((char *)&py + PY_SYMBOLS[i].offset, &p, sizeof p);
    }
    return 1;
}

/* The value of `key=` in resources/neighbor_runtime.txt (first match), or "" */
static void config_value(const char *resources, const char *key, char *out, size_t size) {
    char path[4096];
    out[0] = '\0';
    snprintf(path, sizeof path, "%s%cneighbor_runtime.txt", resources, PATH_SEP);
    FILE *f = fopen(path, "r");
    if (!f) return;
    char line[4096];
    size_t n = strlen(key);
    while (fgets(line, sizeof line, f)) {
        if (strncmp(line, key, n) == 0 && line[n] == '=') {
            line[strcspn(line, "\r\n")] = '\0';
            snprintf(out, size, "%s", line + n + 1);
            break;
        }
    }
    fclose(f);
}

/* ---- finding a Python on the target -------------------------------------------------------------
 * In order: NEIGHBOR_FMU_LIBPYTHON (an explicit choice: its failure is the answer); the python3 on
 * the host's PATH (asked for its shared library); libpython3.X through the system's linker for
 * every supported minor version, newest first; the build machine's library last, and only when its
 * prefix exists. A library is taken only with its standard library: the Python home is PYTHONHOME
 * when the user set it, else the folder above the library that holds lib/python3.X/encodings (so
 * the build machine's paths are never used for another Python). Python's own initialization
 * exits the process when it finds no standard library; checking first keeps the host alive. */
#define MIN_MINOR 9
#define MAX_MINOR 13

static void note(char *tried, size_t size, const char *fmt, ...) {
    size_t used = strlen(tried);
    if (used + 3 >= size) return;
    if (used) {
        memcpy(tried + used, "; ", 3);
        used += 2;
    }
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(tried + used, size - used, fmt, ap);
    va_end(ap);
}

static int file_exists(const char *path) {
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    fclose(f);
    return 1;
}

/* The standard library of Python `version` (3.X) below `home`: its landmark's path in `landmark`. */
static int stdlib_at(const char *home, const char *version, char *landmark, size_t size) {
#ifdef _WIN32
    (void)version;
    snprintf(landmark, size, "%s\\Lib\\encodings\\__init__.py", home);
#else
    snprintf(landmark, size, "%s/lib/python%s/encodings/__init__.py", home, version);
#endif
    return file_exists(landmark);
}

/* The home of the library at `libpath`: it or one of the 3 folders above it holding the standard
   library (pyenv and python.org: <home>/lib/libpython3.X.so; Debian: /usr/lib/<arch>/; Windows:
   <home>/python3X.dll). */
static int home_of_library(const char *libpath, const char *version, char *home, size_t size) {
    char dir[4096], landmark[4200];
    snprintf(dir, sizeof dir, "%s", libpath);
    for (int up = 0; up < 4; up++) {
        char *sep = strrchr(dir, PATH_SEP);
#ifdef _WIN32
        char *alt = strrchr(dir, '/');
        if (alt > sep) sep = alt;
#endif
        if (!sep || sep == dir) return 0;
        *sep = '\0';
        if (stdlib_at(dir, version, landmark, sizeof landmark)) {
            snprintf(home, size, "%s", dir);
            return 1;
        }
    }
    return 0;
}

static lib_handle lib_probe(const char *path) {
#ifdef _WIN32
    return LoadLibraryA(path);
#else
    return dlopen(path, RTLD_NOW | RTLD_LOCAL);  /* made global only once it is chosen */
#endif
}

static void lib_close(lib_handle h) {
#ifdef _WIN32
    FreeLibrary(h);
#else
    dlclose(h);
#endif
}

/* Where the library that holds `symbol` (in `h`) was loaded from. */
static int library_file(lib_handle h, void *symbol, char *out, size_t size) {
#ifdef _WIN32
    (void)symbol;
    DWORD n = GetModuleFileNameA(h, out, (DWORD)size);
    return n > 0 && n < size;
#else
    (void)h;
    Dl_info info;
    if (!dladdr(symbol, &info) || !info.dli_fname) return 0;
    char *real = realpath(info.dli_fname, NULL);  /* Debian: /lib/<arch>/ is /usr/lib/<arch>/ */
    snprintf(out, size, "%s", real ? real : info.dli_fname);
    free(real);
    return 1;
#endif
}

/* Try the CPython library `spec` (a path or a name for the linker), found as `how`. On success
   the handle (made global), its version "3.X" and its home. */
static lib_handle try_library(const char *spec, const char *how, char *version, size_t vsize, char *home,
                              size_t hsize, char *tried, size_t tsize) {
    lib_handle h = lib_probe(spec);
    if (!h) {
        note(tried, tsize, "%s (%s): not found", spec, how);
        return NULL;
    }
    void *sym = lib_sym(h, "Py_GetVersion");
    if (!sym) {
        note(tried, tsize, "%s (%s): not a CPython library", spec, how);
        lib_close(h);
        return NULL;
    }
    const char *(*get_version)(void) = (const char *(*)(void))sym;
    int major = 0, minor = 0;
    if (sscanf(get_version(), "%d.%d", &major, &minor) != 2 || major != 3 || minor < MIN_MINOR) {
        note(tried, tsize, "%s (%s): Python %.12s is not supported (3.%d or newer)", spec, how, get_version(),
             MIN_MINOR);
        lib_close(h);
        return NULL;
    }
    snprintf(version, vsize, "%d.%d", major, minor);
    char file[4096], landmark[4200];
    if (!library_file(h, sym, file, sizeof file)) snprintf(file, sizeof file, "%s", spec);
    const char *user_home = getenv("PYTHONHOME");
    if (user_home && user_home[0]) {
        if (!stdlib_at(user_home, version, landmark, sizeof landmark)) {
            note(tried, tsize, "%s (%s, Python %s): PYTHONHOME=%s has no standard library for it (no %s)", file,
                 how, version, user_home, landmark);
            lib_close(h);
            return NULL;
        }
        snprintf(home, hsize, "%s", user_home);
    } else if (!home_of_library(file, version, home, hsize)) {
        note(tried, tsize, "%s (%s, Python %s): no standard library beside it (no lib/python%s/encodings in the "
             "folders above it; set PYTHONHOME to its prefix)", file, how, version, version);
        lib_close(h);
        return NULL;
    }
#ifndef _WIN32
    /* global from now on: extension modules (numpy) find the C API in the process */
    lib_handle global = dlopen(file, RTLD_NOW | RTLD_GLOBAL);
    if (global) {
        dlclose(h);
        h = global;
    }
#endif
    return h;
}

/* The shared library of the python3 on the host's PATH, asked from that Python ("" if none);
   the command's exit status (127: no python3 on PATH). */
static int python_on_path(char *out, size_t size) {
    out[0] = '\0';
#ifdef _WIN32
    FILE *p = _popen("python -E -S -c \"import sys, os; print(os.path.join(sys.base_prefix, "
                     "'python%d%d.dll' % sys.version_info[:2]))\" 2>NUL", "r");
#else
    FILE *p = popen("python3 -E -S -c \"import os, sysconfig as s; "
                    "print(os.path.join(s.get_config_var('LIBDIR') or '', s.get_config_var('INSTSONAME') or ''))\" "
                    "2>/dev/null", "r");
#endif
    if (!p) return -1;
    if (fgets(out, (int)size, p)) out[strcspn(out, "\r\n")] = '\0';
    else out[0] = '\0';
#ifdef _WIN32
    return _pclose(p);
#else
    int status = pclose(p);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
#endif
}

static void library_name(int minor, char *out, size_t size) {
#ifdef _WIN32
    snprintf(out, size, "python3%d.dll", minor);
#else
    snprintf(out, size, "libpython3.%d.so.1.0", minor);
#endif
}

static lib_handle find_python(const char *resources, char *version, size_t vsize, char *home, size_t hsize) {
    char tried[3000] = "", spec[4096];
    lib_handle h = NULL;
    const char *env = getenv("NEIGHBOR_FMU_LIBPYTHON");
    if (env && env[0]) {
        h = try_library(env, "NEIGHBOR_FMU_LIBPYTHON", version, vsize, home, hsize, tried, sizeof tried);
        if (!h) snprintf(runtime_error, sizeof runtime_error, "no usable Python for this FMU: %s", tried);
        return h;
    }
    int status = python_on_path(spec, sizeof spec);
    if (spec[0] && file_exists(spec))
        h = try_library(spec, "the python3 on PATH", version, vsize, home, hsize, tried, sizeof tried);
    else if (spec[0])
        note(tried, sizeof tried, "the python3 on PATH has no shared library (no %s)", spec);
    else if (status == 127 || status == 9009)  /* sh / cmd.exe: no such command */
        note(tried, sizeof tried, "no python3 on PATH");
    else
        note(tried, sizeof tried, "the python3 on PATH did not answer (exit status %d)", status);
    for (int minor = MAX_MINOR; minor >= MIN_MINOR && !h; minor--) {
        library_name(minor, spec, sizeof spec);
        h = try_library(spec, "system linker", version, vsize, home, hsize, tried, sizeof tried);
    }
    if (!h) {
        char built[4096], built_home[4096], landmark[4200];
        config_value(resources, "libpython", built, sizeof built);
        config_value(resources, "python_home", built_home, sizeof built_home);
        config_value(resources, "python_version", version, vsize);
        if (built[0] && built_home[0] && stdlib_at(built_home, version, landmark, sizeof landmark))
            h = try_library(built, "the build's Python", version, vsize, home, hsize, tried, sizeof tried);
    }
    if (!h)
        snprintf(runtime_error, sizeof runtime_error,
                 "this FMU runs its model in CPython 3.%d to 3.%d with numpy and found none it can use (%s). Install "
                 "CPython 3 with its shared library (e.g. Debian's libpython3.11) and numpy, put its python3 on "
                 "PATH, or set NEIGHBOR_FMU_LIBPYTHON to the library's path", MIN_MINOR, MAX_MINOR, tried);
    return h;
}

/* Mark an interpreter this library just started (GIL held), so that the other FMU libraries of
   ours that find it running know it is not a host's own Python (neighbor_runtime.py reads it). */
static void mark_started_interpreter(void) {
    PyObject *ns = py.DictNew();
    if (!ns) return;
    py.DictSetItemString(ns, "__builtins__", py.EvalGetBuiltins());
    PyObject *r = py.RunString("import sys\nsys._neighbor_cosim_started_python = True\n", PY_FILE_INPUT, ns, ns);
    if (r) py.DecRef(r);
    else py.ErrClear();
    py.DecRef(ns);
}

static int start_runtime_locked(const char *resources) {
    if (runtime_ready) return 1;
    if (runtime_error[0]) return 0;  /* tried in this process before: the same answer, no retry */
    if (process_sym("Py_IsInitialized") && resolve_all(NULL) && py.IsInitialized()) {
        runtime_ready = 1;  /* the host runs Python (or another FMU of ours started one): use it */
        return 1;
    }
    runtime_error[0] = '\0';
    char version[64], home[4096];
    lib_handle handle = find_python(resources, version, sizeof version, home, sizeof home);
    if (!handle) return 0;
    if (!resolve_all(handle)) return 0;
    if (!py.IsInitialized()) {
        void *(*decode)(const char *, size_t *) = (void *(*)(const char *, size_t *))lib_sym(handle, "Py_DecodeLocale");
        void (*set_home)(const void *) = (void (*)(const void *))lib_sym(handle, "Py_SetPythonHome");
        if (!decode || !set_home) {
            snprintf(runtime_error, sizeof runtime_error, "the Python %s library lacks Py_SetPythonHome", version);
            return 0;
        }
        static void *whome = NULL;  /* kept: Python reads it during initialization and after */
        whome = decode(home, NULL);
        if (whome) set_home(whome);
        py.InitializeEx(0);  /* no signal handlers: the host owns the signals */
        runtime_embedded = 1;
        mark_started_interpreter();
        py.EvalSaveThread();  /* release the GIL: every call takes it with PyGILState_Ensure */
    }
    runtime_ready = 1;
    return 1;
}

/* Starting Python must happen once per process, whichever of our FMU libraries (each with its
 * own statics) gets there first, and the others must wait until it has fully started: a lock the
 * whole process shares is needed, and no library of ours can own it. POSIX: the C library's lock
 * of stderr (flockfile: process-wide, recursive, always there; held only while Python starts).
 * Windows: a mutex named after the process. Taken by every instantiation (cheap), so that the
 * runtime's statics a thread reads were written under the lock. */
static int start_runtime(const char *resources) {
#ifdef _WIN32
    char name[96];
    snprintf(name, sizeof name, "Local\\neighbor-cosim-python-start-%lu", (unsigned long)GetCurrentProcessId());
    HANDLE mutex = CreateMutexA(NULL, FALSE, name);
    if (mutex) WaitForSingleObject(mutex, INFINITE);
    int ok = start_runtime_locked(resources);
    if (mutex) {
        ReleaseMutex(mutex);
        CloseHandle(mutex);
    }
#else
    flockfile(stderr);
    int ok = start_runtime_locked(resources);
    funlockfile(stderr);
#endif
    return ok;
}

/* ---- instances ------------------------------------------------------------------------------
 * The front end (neighbor_fmi2.c, neighbor_fmi3.c) defines, before including this file:
 *   HostCallbacks: what the host gave to log with;
 *   host_log(cb, instance name, status, category, text): one message to the host;
 *   GET_CALLS/SET_CALLS: the standard's names of the get/set calls per kind (error messages).
 * Statuses are the standard's numbers, which both versions share (OK 0 ... Fatal 4). */
enum { ST_OK = 0, ST_WARNING = 1, ST_DISCARD = 2, ST_ERROR = 3, ST_FATAL = 4 };
typedef int Status;

/* The value references of a get or set call as the Python tuple the model's get/set receive: a
   master asks for the same lists at every step, and the model keys its prepared plan of the
   call by that tuple (NeighborSlave._get/_set), so the last few are kept, each with a copy of
   its numbers to compare. */
#define VR_CACHED 4
typedef struct {
    unsigned int *copy;
    size_t n;
    PyObject *tuple;
} VrTuple;

typedef struct {
    HostCallbacks cb;
    char *name;
    int logging_on;
    PyObject *slave;
    PyObject *log_queue;  /* the slave's list of pending messages */
    PyObject *m_get[4], *m_set[4];  /* bound get_real ... get_string, set_real ... set_string */
    PyObject *m_do_step;
    VrTuple vr_tuples[2][4][VR_CACHED]; /* [get, set][kind][slot] */
    int vr_next[2][4];                  /* the slot the next new list replaces */
    char **strings;  /* String results, valid until the next call */
    size_t n_strings;
    int broken;  /* a fatal error: every later call returns Fatal */
    /* Values shared with the model (NeighborSlave.share_values; NULL when it does not): the value
     * of every variable by value reference, each one's code (0: through Python; else its role |
     * its kind << 4) and the freshness flags. The arrays belong to the slave object. */
    double *sh_values;
    const int *sh_codes;
    const int *sh_spans;  /* FMI 3.0: elements per value reference (arrays), else NULL */
    int *sh_flags;
    size_t sh_n;
    PyObject *m_publish;  /* the slave's publish: writes every shared output, marks them fresh */
    /* The slave's native step (NeighborSlave.arm_native), three int64 it owns: the address of a
     * compiled int step(context, t, h) that takes the step and publishes without Python (0: none
     * now), its context, and the address of a compiled publish on the same context (0: publish
     * through Python). NULL when the slave shares no values. */
    const long long *sh_native;
    double *sh_clock;     /* FMI 3.0: the model's time (NeighborSlave's _neighbor_clock), which a
                             native step advances; NULL for FMI 2.0 */
    int state;            /* where the standard's state machine is (S_* below) */
    double next_time;     /* where the next doStep must start: the start time (0 until a setup or
                             an initialization says otherwise), then the end of the last step */
} Instance;

/* ---- the standard's state machine ------------------------------------------------------------
 * FMI 2.0 and 3.0 co-simulation allow each call only in some states (FMI 2.0 section 4.2.4, FMI
 * 3.0 section 4.2.1); a call made in another state is refused with fmiError and a message naming
 * the call and the state, and changes nothing. A lifecycle call that fails (fmiError) leaves the
 * instance in the error state, where only gets, fmiReset, fmiSetFMUState and fmiFreeInstance are
 * allowed; a set or get that the model refused (a bad value) leaves it where it was, since the
 * model did not take it. Both standards' states map onto these: */
enum {
    S_INSTANTIATED = 1,   /* after instantiate and reset */
    S_INITIALIZATION = 2, /* between enter and exit initialization mode */
    S_STEPPING = 4,       /* FMI 2.0 stepComplete, FMI 3.0 Step Mode */
    S_STEP_FAILED = 8,    /* a doStep returned fmiDiscard */
    S_TERMINATED = 16,
    S_ERROR = 32
};
#define MASK_SETUP S_INSTANTIATED
#define MASK_ENTER_INIT S_INSTANTIATED
#define MASK_EXIT_INIT S_INITIALIZATION
#define MASK_DO_STEP S_STEPPING
#define MASK_TERMINATE (S_STEPPING | S_STEP_FAILED)
#define MASK_GET (S_INITIALIZATION | S_STEPPING | S_STEP_FAILED | S_TERMINATED | S_ERROR)
#define MASK_SET (S_INSTANTIATED | S_INITIALIZATION | S_STEPPING)

static const char *state_name(int state) {
    switch (state) {
    case S_INSTANTIATED: return "instantiated";
    case S_INITIALIZATION: return "initialization mode";
    case S_STEPPING: return "step mode (initialized)";
    case S_STEP_FAILED: return "step failed (a doStep returned Discard)";
    case S_TERMINATED: return "terminated";
    default: return "error (a call failed; only gets, reset, set state and free are allowed)";
    }
}

static void log_refusal(Instance *inst, const char *text) {
    host_log(&inst->cb, inst->name, 3 /* Error */, "logStatusError", text);
}

/* ST_OK when `what` may be called on `inst` now (its state is in `mask`); else the status the call
   returns: Error (no instance, or the state's refusal logged), Fatal after a fatal error. */
static Status admit(Instance *inst, int mask, const char *what) {
    if (!inst) return ST_ERROR;
    if (inst->broken) return ST_FATAL;
    if (inst->state & mask) return ST_OK;
    char text[512];
    snprintf(text, sizeof text, "%s is not allowed in state %s (the FMI standard's call order)", what,
             state_name(inst->state));
    log_refusal(inst, text);
    return ST_ERROR;
}

/* Roles of shared variables and the flags (NeighborSlave's SHARED_* and FRESH_* numbers) */
enum { SH_INPUT = 1, SH_STATE_OUTPUT = 2, SH_FEEDTHROUGH_OUTPUT = 3 };
enum { FRESH_STATE = 0, FRESH_FEEDTHROUGH = 1 };

enum { KIND_REAL, KIND_INTEGER, KIND_BOOLEAN, KIND_STRING };
static const char *GET_NAMES[] = {"get_real", "get_integer", "get_boolean", "get_string"};
static const char *SET_NAMES[] = {"set_real", "set_integer", "set_boolean", "set_string"};

static char *copy_string(const char *s) {
    size_t n = strlen(s) + 1;
    char *out = (char *)malloc(n);
    if (out) memcpy(out, s, n);
    return out;
}

/* Pass the messages the model queued to the host (ok messages only with logging on). GIL held. */
static void drain_log(Instance *inst) {
    if (!inst->log_queue || py.ListSize(inst->log_queue) <= 0) return;
    PyObject *drain = py.DictGetItemString(loader, "drain");
    PyObject *args = py.TupleNew(1);
    py.IncRef(inst->slave);
    py.TupleSetItem(args, 0, inst->slave);
    PyObject *items = py.CallObject(drain, args);
    py.DecRef(args);
    if (!items) {
        py.ErrClear();
        return;
    }
    Py_ssize_t n = py.ListSize(items);
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *t = py.ListGetItem(items, i);
        long status = py.LongAsLong(py.TupleGetItem(t, 0));
        const char *category = py.UnicodeAsUTF8(py.TupleGetItem(t, 1));
        const char *text = py.UnicodeAsUTF8(py.TupleGetItem(t, 2));
        if (status > ST_OK || inst->logging_on)
            host_log(&inst->cb, inst->name, (Status)status, category ? category : "logAll", text ? text : "");
    }
    py.DecRef(items);
}

/* A Python exception is pending: log it and return its status (Error or Fatal). GIL held. */
static Status fail(Instance *inst, const char *call) {
    PyObject *type = NULL, *value = NULL, *tb = NULL;
    py.ErrFetch(&type, &value, &tb);
    if (type) py.ErrNormalize(&type, &value, &tb);
    Status status = ST_ERROR;
    PyObject *describe = loader ? py.DictGetItemString(loader, "describe") : NULL;
    PyObject *res = NULL;
    if (describe) {
        PyObject *fetched[3] = {type, value, tb};
        PyObject *args = py.TupleNew(4);
        for (int i = 0; i < 3; i++) {
            PyObject *o = fetched[i];
            if (!o) {
                o = py.DictGetItemString(loader, "NONE");
                py.IncRef(o);
            }
            py.TupleSetItem(args, i, o);  /* steals the fetched references */
        }
        type = value = tb = NULL;
        py.TupleSetItem(args, 3, py.UnicodeFromString(call));
        res = py.CallObject(describe, args);
        py.DecRef(args);
    }
    if (res) {
        status = (Status)py.LongAsLong(py.TupleGetItem(res, 0));
        const char *text = py.UnicodeAsUTF8(py.TupleGetItem(res, 1));
        host_log(&inst->cb, inst->name, status, status == ST_FATAL ? "logStatusFatal" : "logStatusError",
                 text ? text : call);
        py.DecRef(res);
    } else {
        /* no loader yet (or it failed): the exception's own text */
        py.ErrClear();
        PyObject *str = value ? py.Str(value) : NULL;
        const char *text = str ? py.UnicodeAsUTF8(str) : NULL;
        char line[2048];
        snprintf(line, sizeof line, "%s: %s", call, text ? text : "failed");
        host_log(&inst->cb, inst->name, ST_ERROR, "logStatusError", line);
        if (str) py.DecRef(str);
        py.ErrClear();
    }
    if (type) py.DecRef(type);
    if (value) py.DecRef(value);
    if (tb) py.DecRef(tb);
    if (status == ST_FATAL) inst->broken = 1;
    return status;
}

/* Call fn(args...) (a new tuple, stolen); the result (new reference) or NULL with the status set. */
static PyObject *call(Instance *inst, PyObject *fn, PyObject *args, const char *what, Status *status) {
    PyObject *res = py.CallObject(fn, args);
    if (args) py.DecRef(args);
    *status = res ? ST_OK : fail(inst, what);
    drain_log(inst);
    return res;
}

static PyObject *method(Instance *inst, const char *name) { return py.GetAttrString(inst->slave, name); }

static PyObject *tuple_of(int n, ...) {
    va_list ap;
    va_start(ap, n);
    PyObject *t = py.TupleNew(n);
    for (int i = 0; i < n; i++) py.TupleSetItem(t, i, va_arg(ap, PyObject *));
    va_end(ap);
    return t;
}

static PyObject *vr_list(const unsigned int vr[], size_t n) {
    PyObject *list = py.ListNew((Py_ssize_t)n);
    for (size_t i = 0; i < n; i++) py.ListSetItem(list, (Py_ssize_t)i, py.LongFromUnsignedLong(vr[i]));
    return list;
}

/* A new reference to the tuple of vr[0 .. n) for a get (set = 0) or set (set = 1) of `kind`. */
static PyObject *vr_tuple(Instance *inst, int set, int kind, const unsigned int vr[], size_t n) {
    VrTuple *slots = inst->vr_tuples[set][kind];
    for (int i = 0; i < VR_CACHED; i++) {
        VrTuple *c = &slots[i];
        if (c->tuple && c->n == n && (n == 0 || memcmp(c->copy, vr, n * sizeof *vr) == 0)) {
            py.IncRef(c->tuple);
            return c->tuple;
        }
    }
    PyObject *t = py.TupleNew((Py_ssize_t)n);
    for (size_t i = 0; i < n; i++) py.TupleSetItem(t, (Py_ssize_t)i, py.LongFromUnsignedLong(vr[i]));
    unsigned int *copy = (unsigned int *)malloc(n ? n * sizeof *vr : 1);
    if (!copy) return t;  /* not kept */
    if (n) memcpy(copy, vr, n * sizeof *vr);
    VrTuple *c = &slots[inst->vr_next[set][kind]];
    inst->vr_next[set][kind] = (inst->vr_next[set][kind] + 1) % VR_CACHED;
    if (c->tuple) py.DecRef(c->tuple);
    free(c->copy);
    c->copy = copy;
    c->n = n;
    c->tuple = t;
    py.IncRef(t);
    return t;
}

static PyObject *none_ref(void) {
    PyObject *none = py.DictGetItemString(loader, "NONE");
    py.IncRef(none);
    return none;
}

#define ENTER(c, what)                                                 \
    Instance *inst = (Instance *)(c);                                  \
    if (!inst) return ST_ERROR;                                        \
    if (inst->broken) return ST_FATAL;                                 \
    int gil = py.GILStateEnsure();                                     \
    Status status = ST_OK;                                             \
    (void)status;
#define LEAVE() py.GILStateRelease(gil)

/* FMI call `what`: the slave's method `name` without arguments (or with `make_args(data)`),
   its result ignored. */
static Status call_method(void *c, const char *what, const char *name, PyObject *(*make_args)(void *), void *data) {
    ENTER(c, what)
    PyObject *fn = method(inst, name);
    if (!fn) {
        status = fail(inst, what);
    } else {
        PyObject *res = call(inst, fn, make_args ? make_args(data) : NULL, what, &status);
        if (res) py.DecRef(res);
        py.DecRef(fn);
    }
    LEAVE();
    return status;
}

/* file:///a/b, file:/a/b, file://host/a/b (percent-decoded) or a plain path -> path */
static void uri_to_path(const char *uri, char *out, size_t size) {
    const char *p = uri;
    if (strncmp(p, "file://", 7) == 0) {
        p += 7;
        if (*p != '/') p = strchr(p, '/') ? strchr(p, '/') : p;  /* skip a host name */
    } else if (strncmp(p, "file:", 5) == 0) {
        p += 5;
    }
#ifdef _WIN32
    if (p[0] == '/' && p[1] && p[2] == ':') p++;  /* /C:/dir -> C:/dir */
#endif
    size_t k = 0;
    for (; *p && k + 1 < size; p++) {
        if (*p == '%' && p[1] && p[2]) {
            char hex[3] = {p[1], p[2], 0};
            out[k++] = (char)strtol(hex, NULL, 16);
            p += 2;
        } else {
            out[k++] = *p;
        }
    }
    while (k > 0 && (out[k - 1] == '/' || out[k - 1] == '\\')) k--;  /* no trailing separator */
    out[k] = '\0';
}

/* Point the instance at the slave's shared values (after instantiation and reset, which builds new
   arrays). GIL held. 0 with a Python error pending if the slave's answer is malformed. */
static int link_shared(Instance *inst) {
    inst->sh_values = NULL;
    inst->sh_codes = NULL;
    inst->sh_spans = NULL;
    inst->sh_flags = NULL;
    inst->sh_native = NULL;
    inst->sh_clock = NULL;
    inst->sh_n = 0;
    if (inst->m_publish) {
        py.DecRef(inst->m_publish);
        inst->m_publish = NULL;
    }
    PyObject *fn = py.DictGetItemString(loader, "shared_memory");  /* borrowed */
    if (!fn) return 1;  /* a loader without it: every value through Python */
    py.IncRef(inst->slave);
    PyObject *args = tuple_of(1, inst->slave);
    PyObject *res = py.CallObject(fn, args);
    py.DecRef(args);
    if (!res) return 0;
    int ok = 1;
    if (res != py.DictGetItemString(loader, "NONE")) {
        void *values = py.LongAsVoidPtr(py.TupleGetItem(res, 0));
        void *codes = py.LongAsVoidPtr(py.TupleGetItem(res, 1));
        void *flags = py.LongAsVoidPtr(py.TupleGetItem(res, 2));
        long n = py.LongAsLong(py.TupleGetItem(res, 3));
        void *spans = py.LongAsVoidPtr(py.TupleGetItem(res, 4));  /* NULL (0) without arrays */
        void *native = py.LongAsVoidPtr(py.TupleGetItem(res, 5));  /* NULL (0): always through Python */
        void *clock = py.LongAsVoidPtr(py.TupleGetItem(res, 6));  /* NULL (0) for FMI 2.0 */
        inst->m_publish = method(inst, "publish");
        if (py.ErrOccurred() || !values || !codes || !flags || n < 0 || !inst->m_publish) {
            ok = 0;
        } else {
            inst->sh_values = (double *)values;
            inst->sh_codes = (const int *)codes;
            inst->sh_flags = (int *)flags;
            inst->sh_spans = (const int *)spans;
            inst->sh_native = (const long long *)native;
            inst->sh_clock = (double *)clock;
            inst->sh_n = (size_t)n;
        }
    }
    py.DecRef(res);
    return ok;
}

static void release_instance(Instance *inst) {
    if (inst->m_publish) py.DecRef(inst->m_publish);
    inst->m_publish = NULL;
    inst->sh_values = NULL;
    for (int k = 0; k < 4; k++) {
        if (inst->m_get[k]) py.DecRef(inst->m_get[k]);
        if (inst->m_set[k]) py.DecRef(inst->m_set[k]);
    }
    if (inst->m_do_step) py.DecRef(inst->m_do_step);
    for (int d = 0; d < 2; d++)
        for (int k = 0; k < 4; k++)
            for (int i = 0; i < VR_CACHED; i++) {
                VrTuple *c = &inst->vr_tuples[d][k][i];
                if (c->tuple) py.DecRef(c->tuple);
                free(c->copy);
                c->tuple = NULL;
                c->copy = NULL;
            }
    if (inst->log_queue) py.DecRef(inst->log_queue);
    if (inst->slave) py.DecRef(inst->slave);
}

/* A new instance of the model in the FMU whose resources folder is `resources` (a path), or NULL
   with the reason in the host's log. `call` names the standard's call in messages. */
static Instance *new_instance(const char *call_name, const char *name, const char *token, const char *resources,
                              int visible, int logging_on, HostCallbacks cb) {
    if (!start_runtime(resources)) {
        host_log(&cb, name, ST_ERROR, "logStatusError", runtime_error);
        return NULL;
    }
    Instance *inst = (Instance *)calloc(1, sizeof(Instance));
    if (!inst) return NULL;
    inst->cb = cb;
    inst->name = copy_string(name);
    inst->logging_on = logging_on ? 1 : 0;
    inst->state = S_INSTANTIATED;
    int gil = py.GILStateEnsure();
    /* the library's lock, waited for without the GIL (a thread holding the lock may need it) */
    void *thread_state = py.EvalSaveThread();
    runtime_lock();
    py.EvalRestoreThread(thread_state);
    Status status = ST_OK;
    if (!loader) {
        char path[4200];
        snprintf(path, sizeof path, "%s%cneighbor_runtime.py", resources, PATH_SEP);
        FILE *f = fopen(path, "rb");
        char *code = NULL;
        if (f) {
            fseek(f, 0, SEEK_END);
            long n = ftell(f);
            fseek(f, 0, SEEK_SET);
            code = (char *)calloc((size_t)n + 1, 1);
            if (code && fread(code, 1, (size_t)n, f) != (size_t)n) {
                free(code);
                code = NULL;
            }
            fclose(f);
        }
        if (!code) {
            char text[4400];
            snprintf(text, sizeof text, "the FMU's resources lack neighbor_runtime.py (no %s: is the resource "
                     "location right?)", path);
            host_log(&cb, name, ST_ERROR, "logStatusError", text);
            runtime_unlock();
            py.GILStateRelease(gil);
            free(inst->name);
            free(inst);
            return NULL;
        }
        /* The loader's namespace is a module of the interpreter named after a hash of its code and
         * the FMU's GUID, so unloading and loading the library again (a host that frees it after
         * every run) reuses it instead of leaving one more copy behind, and no two FMU builds
         * share one. */
        unsigned long long h = 1469598103934665603ULL;  /* FNV-1a 64 */
        for (const unsigned char *p = (const unsigned char *)code; *p; p++) h = (h ^ *p) * 1099511628211ULL;
        for (const unsigned char *p = (const unsigned char *)(token ? token : ""); *p; p++)
            h = (h ^ *p) * 1099511628211ULL;
        char module_name[64];
        snprintf(module_name, sizeof module_name, "_neighbor_runtime_%016llx", h);
        PyObject *module = py.ImportAddModule(module_name);  /* borrowed, kept in sys.modules */
        PyObject *ns = module ? py.ModuleGetDict(module) : NULL;  /* borrowed */
        if (ns && !py.DictGetItemString(ns, "instantiate")) {
            py.DictSetItemString(ns, "__builtins__", py.EvalGetBuiltins());
            PyObject *r = py.RunString(code, PY_FILE_INPUT, ns, ns);
            if (r) py.DecRef(r);
            else ns = NULL;
        }
        free(code);
        if (!ns) {
            status = fail(inst, "loading neighbor_runtime.py");
        } else {
            py.IncRef(ns);
            loader = ns;
        }
    }
    runtime_unlock();  /* the loader is there (or failed): the model's import work locks in Python */
    if (loader) {
        PyObject *fn = py.DictGetItemString(loader, "instantiate");
        PyObject *args = tuple_of(6, py.UnicodeFromString(resources), py.UnicodeFromString(name),
                                  py.UnicodeFromString(token ? token : ""), py.BoolFromLong(visible),
                                  py.BoolFromLong(runtime_embedded), py.BoolFromLong(inst->logging_on));
        PyObject *res = py.CallObject(fn, args);
        py.DecRef(args);
        if (!res) {
            status = fail(inst, call_name);
        } else {
            inst->slave = res;
            inst->log_queue = method(inst, "log_queue");
            for (int k = 0; k < 4 && inst->log_queue; k++) {
                inst->m_get[k] = method(inst, GET_NAMES[k]);
                inst->m_set[k] = method(inst, SET_NAMES[k]);
                if (!inst->m_get[k] || !inst->m_set[k]) status = fail(inst, call_name);
            }
            inst->m_do_step = method(inst, "do_step");
            if (!inst->log_queue || !inst->m_do_step) status = fail(inst, call_name);
            else if (!link_shared(inst)) status = fail(inst, call_name);
            drain_log(inst);
        }
    }
    if (status != ST_OK) {
        if (inst->slave) release_instance(inst);
        py.GILStateRelease(gil);
        free(inst->name);
        free(inst);
        return NULL;
    }
    py.GILStateRelease(gil);
    return inst;
}

static void free_strings(Instance *inst) {
    for (size_t i = 0; i < inst->n_strings; i++) free(inst->strings[i]);
    free(inst->strings);
    inst->strings = NULL;
    inst->n_strings = 0;
}

static void free_instance(Instance *inst) {
    if (!inst) return;
    int gil = py.GILStateEnsure();
    release_instance(inst);
    py.GILStateRelease(gil);
    free_strings(inst);
    free(inst->name);
    free(inst);
}

typedef struct { int tol_defined, stop_defined; double tol, start, stop; } Setup;
static PyObject *setup_args(void *data) {
    Setup *s = (Setup *)data;
    return tuple_of(3, py.FloatFromDouble(s->start), s->stop_defined ? py.FloatFromDouble(s->stop) : none_ref(),
                    s->tol_defined ? py.FloatFromDouble(s->tol) : none_ref());
}

/* The state a lifecycle call that returned `status` leaves the instance in: `next` when it
   succeeded, the error state when it failed (Fatal marks the instance broken in fail()). */
static Status enter_state(Instance *inst, Status status, int next) {
    if (status <= ST_WARNING) inst->state = next;
    else if (status == ST_ERROR) inst->state = S_ERROR;
    return status;
}

/* A lifecycle call (`what`, the slave's method `name`) allowed in `mask`, leading to `next`. */
static Status lifecycle(void *c, const char *what, const char *name, PyObject *(*make_args)(void *), void *data,
                        int mask, int next) {
    Status refused = admit((Instance *)c, mask, what);
    if (refused) return refused;
    return enter_state((Instance *)c, call_method(c, what, name, make_args, data), next);
}

/* The start time a setup or an initialization announced: where the first doStep must start. */
static void start_time(void *c, double t) {
    ((Instance *)c)->next_time = t;
}

static Status reset_instance(void *c, const char *what) {
    ENTER(c, what)
    PyObject *fn = py.DictGetItemString(loader, "reset");
    py.IncRef(inst->slave);
    PyObject *res = call(inst, fn, tuple_of(1, inst->slave), what, &status);
    if (res) py.DecRef(res);  /* a fresh model in the same slave object: the bound methods stay valid */
    if (res && !link_shared(inst)) status = fail(inst, what);  /* but its shared arrays are new */
    LEAVE();
    inst->next_time = 0.0;  /* as after instantiation */
    return enter_state(inst, status, S_INSTANTIATED);
}

/* ---- values ----------------------------------------------------------------------------------
 * The shared-memory path of a get or set. A value reference stands for sh_spans[vr] elements from
 * vr on (FMI 3.0: an array's elements, 0 for a value reference inside an array) or one (FMI 2.0,
 * no spans). all_shared is 1 when every element is a shared variable of this kind (a get: any
 * role; a set: an input) and they are n_values in all; 0 otherwise (the call then goes through
 * Python, which gives the same values or the error). */
static size_t span_of(const Instance *inst, unsigned int vr) {
    return inst->sh_spans ? (size_t)inst->sh_spans[vr] : 1;
}

static int all_shared(const Instance *inst, int kind, const unsigned int vr[], size_t nvr, size_t n_values,
                      int set, int *needs) {
    if (!inst->sh_values || kind == KIND_STRING) return 0;
    int need = 0;
    size_t count = 0;
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] >= inst->sh_n) return 0;
        size_t span = span_of(inst, vr[i]);
        if (!span || vr[i] + span > inst->sh_n) return 0;
        for (size_t j = 0; j < span; j++) {
            int code = inst->sh_codes[vr[i] + j];
            int role = code & 15;
            if (!role || (code >> 4) != kind || (set && role != SH_INPUT)) return 0;
            if (role == SH_STATE_OUTPUT) need |= 1;
            else if (role == SH_FEEDTHROUGH_OUTPUT) need |= 3;
        }
        count += span;
    }
    if (count != n_values) return 0;
    if (needs) *needs = need;
    return 1;
}

static void copy_shared_out(const Instance *inst, int kind, const unsigned int vr[], size_t nvr, void *out,
                            size_t bool_size) {
    const double *v = inst->sh_values;
    size_t k = 0;
    for (size_t i = 0; i < nvr; i++) {
        size_t span = span_of(inst, vr[i]);
        for (size_t j = 0; j < span; j++, k++) {
            double x = v[vr[i] + j];
            switch (kind) {
            case KIND_REAL: ((double *)out)[k] = x; break;
            case KIND_INTEGER: ((int *)out)[k] = (int)x; break;
            default:
                if (bool_size == 1) ((unsigned char *)out)[k] = x != 0.0;
                else ((int *)out)[k] = x != 0.0;
            }
        }
    }
}

/* A model's native step or publish (NeighborSlave.arm_native): 0 when it did its work. */
typedef int (*NativeStep)(long long context, double t, double h);

/* A get of shared variables: from memory, after one call of the model's publish when an output
   asked for is not fresh (a step, a parameter or, for a feedthrough output, an input changed). */
static Status get_shared(Instance *inst, int kind, const unsigned int vr[], size_t nvr, void *out,
                         size_t bool_size, int needs, const char *what) {
    int stale = ((needs & 1) && !inst->sh_flags[FRESH_STATE]) || ((needs & 2) && !inst->sh_flags[FRESH_FEEDTHROUGH]);
    const long long *native = inst->sh_native;
    if (stale && !inst->broken && native && native[0] && native[2]) {
        /* the model's compiled publish (armed with its step): writes the outputs, marks them fresh;
           non-zero when it changed nothing (the Python publish below then raises the error) */
        NativeStep publish = (NativeStep)(intptr_t)native[2];
        stale = publish(native[1], 0.0, 0.0) != 0;
    }
    if (stale) {
        int gil = py.GILStateEnsure();
        Status status = ST_OK;
        PyObject *res = call(inst, inst->m_publish, NULL, what, &status);
        if (res) py.DecRef(res);
        py.GILStateRelease(gil);
        if (!res) return status;
    }
    copy_shared_out(inst, kind, vr, nvr, out, bool_size);
    return ST_OK;
}

static void set_shared(Instance *inst, int kind, const unsigned int vr[], size_t nvr, const void *in,
                       size_t bool_size) {
    double *v = inst->sh_values;
    size_t k = 0;
    for (size_t i = 0; i < nvr; i++) {
        size_t span = span_of(inst, vr[i]);
        for (size_t j = 0; j < span; j++, k++) {
            double *dst = &v[vr[i] + j];
            switch (kind) {
            case KIND_REAL: *dst = ((const double *)in)[k]; break;
            case KIND_INTEGER: *dst = (double)((const int *)in)[k]; break;
            default: *dst = (bool_size == 1 ? ((const unsigned char *)in)[k] : ((const int *)in)[k]) ? 1.0 : 0.0;
            }
        }
    }
    inst->sh_flags[FRESH_FEEDTHROUGH] = 0;  /* the outputs that depend on inputs */
}

/* A get or set with value references or values missing where the host said there are some. */
static int arrays_given(Instance *inst, const unsigned int vr[], size_t nvr, const void *values, size_t n_values,
                        const char *what) {
    if ((nvr && !vr) || (n_values && !values)) {
        char text[256];
        snprintf(text, sizeof text, "%s: %s is NULL for %lu entries", what, nvr && !vr ? "the value reference array"
                 : "the value array", (unsigned long)(nvr && !vr ? nvr : n_values));
        log_refusal(inst, text);
        return 0;
    }
    return 1;
}

/* `get` fills out[0 .. expected) from the model's list of values (for FMI 3.0 through the loader,
 * which expands arrays; `expected` is then the host's nValues), or from the shared values;
 * Booleans are written as `bool_size`-byte integers (FMI 2.0: int, FMI 3.0: bool). */
static Status get_values(void *c, int kind, const unsigned int vr[], size_t nvr, void *out, size_t expected,
                         int via_loader, size_t bool_size, const char *what) {
    Instance *shared = (Instance *)c;
    Status refused = admit(shared, MASK_GET, what);
    if (refused) return refused;
    if (!arrays_given(shared, vr, nvr, out, expected, what)) return ST_ERROR;
    int needs = 0;
    if ((!via_loader || shared->sh_spans) && all_shared(shared, kind, vr, nvr, expected, 0, &needs))
        return get_shared(shared, kind, vr, nvr, out, bool_size, needs, what);
    ENTER(c, what)
    PyObject *res;
    if (via_loader) {
        PyObject *fn = py.DictGetItemString(loader, "get_values");
        py.IncRef(inst->slave);
        res = call(inst, fn, tuple_of(3, inst->slave, py.LongFromLong(kind), vr_list(vr, nvr)), what, &status);
    } else {
        res = call(inst, inst->m_get[kind], tuple_of(1, vr_tuple(inst, 0, kind, vr, nvr)), what, &status);
    }
    if (res) {
        if (kind == KIND_STRING) {
            free_strings(inst);
            inst->strings = (char **)calloc(expected ? expected : 1, sizeof(char *));
            inst->n_strings = expected;
        }
        if (py.ListSize(res) != (Py_ssize_t)expected) {
            char text[256];
            snprintf(text, sizeof text, "%s: the variables asked for have %ld values, the host gave room for %lu",
                     what, (long)py.ListSize(res), (unsigned long)expected);
            host_log(&inst->cb, inst->name, ST_ERROR, "logStatusError", text);
            status = ST_ERROR;
            expected = 0;
        }
        for (size_t i = 0; i < expected; i++) {
            PyObject *item = py.ListGetItem(res, (Py_ssize_t)i);
            switch (kind) {
            case KIND_REAL: ((double *)out)[i] = py.FloatAsDouble(item); break;
            case KIND_INTEGER: ((int *)out)[i] = (int)py.LongAsLong(item); break;
            case KIND_BOOLEAN:
                if (bool_size == 1) ((unsigned char *)out)[i] = py.IsTrue(item) ? 1 : 0;
                else ((int *)out)[i] = py.IsTrue(item) ? 1 : 0;
                break;
            default: {
                const char *s = py.UnicodeAsUTF8(item);
                inst->strings[i] = copy_string(s ? s : "");
                ((const char **)out)[i] = inst->strings[i];
            }
            }
        }
        if (py.ErrOccurred()) status = fail(inst, what);
        py.DecRef(res);
    }
    LEAVE();
    return status;
}

static Status set_values(void *c, int kind, const unsigned int vr[], size_t nvr, const void *in, size_t n_in,
                         int via_loader, size_t bool_size, const char *what) {
    Instance *shared = (Instance *)c;
    Status refused = admit(shared, MASK_SET, what);
    if (refused) return refused;
    if (!arrays_given(shared, vr, nvr, in, n_in, what)) return ST_ERROR;
    if ((!via_loader || shared->sh_spans) && all_shared(shared, kind, vr, nvr, n_in, 1, NULL)) {
        set_shared(shared, kind, vr, nvr, in, bool_size);
        return ST_OK;
    }
    ENTER(c, what)
    PyObject *values = py.ListNew((Py_ssize_t)n_in);
    for (size_t i = 0; i < n_in; i++) {
        PyObject *v;
        switch (kind) {
        case KIND_REAL: v = py.FloatFromDouble(((const double *)in)[i]); break;
        case KIND_INTEGER: v = py.LongFromLong(((const int *)in)[i]); break;
        case KIND_BOOLEAN:
            v = py.BoolFromLong(bool_size == 1 ? ((const unsigned char *)in)[i] : ((const int *)in)[i]);
            break;
        default: {
            const char *s = ((const char *const *)in)[i];
            v = py.UnicodeFromString(s ? s : "");
            if (!v) v = py.UnicodeFromString("");  /* not UTF-8: the model refuses it as a value */
        }
        }
        py.ListSetItem(values, (Py_ssize_t)i, v);
    }
    PyObject *res;
    if (via_loader) {
        PyObject *fn = py.DictGetItemString(loader, "set_values");
        py.IncRef(inst->slave);
        res = call(inst, fn, tuple_of(4, inst->slave, py.LongFromLong(kind), vr_list(vr, nvr), values), what,
                   &status);
    } else {
        res = call(inst, inst->m_set[kind], tuple_of(2, vr_tuple(inst, 1, kind, vr, nvr), values), what, &status);
    }
    if (res) py.DecRef(res);
    LEAVE();
    return status;
}

/* ---- state ----------------------------------------------------------------------------------
 * An FMU state is the model's (a Python object) with where the state machine and the clock were:
 * setting it puts the instance back there (FMI 2.0 allows it after an error). */
typedef struct {
    PyObject *model;
    int state;
    double next_time;
} SavedState;

static Status get_state(void *c, void **state, const char *what) {
    ENTER(c, what)
    if (!state) {
        char text[128];
        snprintf(text, sizeof text, "%s: no place for the state given (NULL)", what);
        log_refusal(inst, text);
        LEAVE();
        return ST_ERROR;
    }
    PyObject *fn = method(inst, "_get_fmu_state");
    PyObject *res = fn ? call(inst, fn, NULL, what, &status) : NULL;
    if (!fn) status = fail(inst, what);
    if (fn) py.DecRef(fn);
    if (res) {
        SavedState *saved = (SavedState *)*state;  /* FMI: a given state is overwritten */
        if (!saved) saved = (SavedState *)calloc(1, sizeof(SavedState));
        if (!saved) {
            py.DecRef(res);
            status = ST_ERROR;
        } else {
            if (saved->model) py.DecRef(saved->model);
            saved->model = res;
            saved->state = inst->state;
            saved->next_time = inst->next_time;
            *state = saved;
        }
    }
    LEAVE();
    return status;
}

static Status set_state(void *c, void *state, const char *what) {
    ENTER(c, what)
    SavedState *saved = (SavedState *)state;
    if (!saved || !saved->model) {
        char text[128];
        snprintf(text, sizeof text, "%s: no state given", what);
        host_log(&inst->cb, inst->name, ST_ERROR, "logStatusError", text);
        LEAVE();
        return ST_ERROR;
    }
    PyObject *fn = method(inst, "_set_fmu_state");
    if (!fn) {
        status = fail(inst, what);
    } else {
        py.IncRef(saved->model);
        PyObject *res = call(inst, fn, tuple_of(1, saved->model), what, &status);
        if (res) py.DecRef(res);
        py.DecRef(fn);
    }
    LEAVE();
    if (status <= ST_WARNING) {
        inst->state = saved->state;
        inst->next_time = saved->next_time;
    }
    return status;
}

static Status free_state(void *c, void **state) {
    ENTER(c, "free state")
    if (state && *state) {
        SavedState *saved = (SavedState *)*state;
        if (saved->model) py.DecRef(saved->model);
        free(saved);
        *state = NULL;
    }
    LEAVE();
    return ST_OK;
}

static Status unsupported(void *c, const char *what) {
    Instance *inst = (Instance *)c;
    if (inst) {
        char text[256];
        snprintf(text, sizeof text, "%s is not supported by this FMU", what);
        host_log(&inst->cb, inst->name, ST_ERROR, "logStatusError", text);
    }
    return ST_ERROR;
}

/* doStep: OK, Discard when the model could not complete the step (do_step returned False);
   refused out of the state machine's order, with a non-positive step or a communication point
   that is not where the last step ended. */
static Status step_model(void *c, double t, double h, const char *what);
static Status do_step(void *c, double t, double h, const char *what) {
    Instance *checked = (Instance *)c;
    Status refused = admit(checked, MASK_DO_STEP, what);
    if (refused) return refused;
    char text[512];
    if (!(h > 0.0) || h > 1e300 || t != t || t > 1e300 || t < -1e300) {  /* NaN fails every comparison */
        snprintf(text, sizeof text, "%s: the communication step size must be positive and finite and the "
                 "communication point finite (got currentCommunicationPoint %.17g, communicationStepSize %.17g)",
                 what, t, h);
        log_refusal(checked, text);
        return ST_ERROR;
    }
    double expected = checked->next_time, scale = expected < 0 ? -expected : expected;
    double gap = t - expected;
    if ((gap < 0 ? -gap : gap) > 1e-10 * (scale > 1.0 ? scale : 1.0)) {  /* round-off of t + h sums */
        snprintf(text, sizeof text, "%s: currentCommunicationPoint %.17g is not where the last step ended "
                 "(%.17g): communication points must be contiguous", what, t, expected);
        log_refusal(checked, text);
        return ST_ERROR;
    }
    Status stepped = step_model(c, t, h, what);
    if (stepped <= ST_WARNING) {
        checked->next_time = t + h;
    } else if (stepped == ST_DISCARD) {
        checked->state = S_STEP_FAILED;
    } else if (stepped == ST_ERROR) {
        checked->state = S_ERROR;
    }
    return stepped;
}

/* system_ssp's master, for a component it suspended (nc:Schedule): the component's clock jumps to
   `t`, where its next doStep starts (a non-standard call; other hosts never jump). */
static Status skip_to(void *c, double t) {
    Status refused = admit((Instance *)c, MASK_DO_STEP, "neighborSkipTo");
    if (refused) return refused;
    ((Instance *)c)->next_time = t;
    return ST_OK;
}

static Status step_model(void *c, double t, double h, const char *what) {
    const Instance *armed = (const Instance *)c;
    if (armed && !armed->broken && armed->sh_native && armed->sh_native[0]) {
        /* the model's compiled step: no Python, no GIL (it touches only the slave's arrays) */
        NativeStep step = (NativeStep)(intptr_t)armed->sh_native[0];
        if (step(armed->sh_native[1], t, h) == 0) {
            if (armed->sh_clock) armed->sh_clock[0] = t + h;  /* as the FMI 3.0 loader's Python step */
            return ST_OK;
        }
        /* it changed nothing: the Python step below takes it, or reports why it cannot */
    }
    ENTER(c, what)  /* a sharing model's step publishes its outputs (or leaves them stale) itself */
    PyObject *res = call(inst, inst->m_do_step, tuple_of(2, py.FloatFromDouble(t), py.FloatFromDouble(h)), what,
                         &status);
    if (res) {
        int ok = py.IsTrue(res);
        if (ok < 0) status = fail(inst, what);
        else if (!ok) status = ST_DISCARD;
        py.DecRef(res);
    }
    LEAVE();
    return status;
}
