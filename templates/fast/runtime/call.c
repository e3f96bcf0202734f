/* Runtime of eomgen's fast backend: the Python interface every generated `_fast.c` shares,
 * i.e. the table entry of a function (function_t), parsing of a call's arrays, parameters and
 * keywords (parse), and the loop of a kernel over one state or a batch (evaluate).
 *
 * The generated module defines, before this text: NQ (entries of q), NV (joints), NP (parameters kept symbolic),
 * MAX_IN (most vector inputs of a function), MAX_LEN (the longest of them), parameter_names[NP + 1] (NULL-terminated),
 * parameter_defaults[NP + 1], parameter_has_default[NP + 1] and renamed_parameters[][2] ({name,
 * keyword} pairs ending with {NULL, NULL}); and includes Python.h, NumPy's
 * arrayobject.h, <math.h> and <string.h>, as this file does.
 *
 * Real C source, not a template: eomgen copies the text below the marker line into the module
 * (eomgen.codegen.backends.fast_backend.runtime_source), and tests/test_fast_runtime_c.py
 * compiles it on its own with -Wall -Wextra -Werror. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#if defined(__unix__) || defined(__APPLE__)
#include <pthread.h>
#include <sched.h>
#include <unistd.h>
#endif

/* eomgen: the generated module holds the text below this line. */
typedef void (*kernel_t)(const double *const *, const double *, double *);

/* A batch goes EOM_LANES states at a time through a function's lanes kernel where it has one:
 * the same arithmetic on GCC/Clang vectors of doubles (a state per lane: the compiler emits
 * SIMD instructions), the remaining states through the one-state kernel. Without the vector
 * extension there are no lanes kernels (EOM_LANES 1). */
#if defined(__GNUC__)
#define EOM_LANES 4
typedef double eom_lanes __attribute__((vector_size(8 * EOM_LANES)));
#define EOM_LANE(vector, lane) ((vector)[lane])
#else
#define EOM_LANES 1
typedef double eom_lanes;
#define EOM_LANE(vector, lane) (vector)
#endif
typedef void (*lanes_kernel_t)(const eom_lanes *const *, const eom_lanes *, eom_lanes *);

typedef struct {
    const char *name;
    int n_in;
    const char *inputs[MAX_IN];
    int rows, cols;  /* cols 0: a vector of rows entries */
    kernel_t kernel;
    int sizes[MAX_IN];  /* length of each input (0: NV) */
    lanes_kernel_t lanes;  /* NULL: the batch goes state by state */
    long operations;  /* arithmetic operations per state (0: unknown, a batch stays on one thread) */
} function_t;

static PyObject *ill_conditioned_warning = NULL;  /* IllConditionedWarning */
static PyObject *lin_alg_error = NULL;            /* numpy.linalg.LinAlgError */

/* The parsed call: input arrays (float64, C-contiguous), parameters, number of states. */
typedef struct {
    PyArrayObject *arrays[MAX_IN];
    double p[NP + 1];
    npy_intp states;
    int single;
    int return_condition;
    double damping;
} call_t;


/* The first states of a batch, EOM_LANES at a time, through f's lanes kernel: each input entry
 * gathered across the states into a vector, the parameters broadcast, the results scattered
 * back. Returns the number of states done (a multiple of EOM_LANES; 0 when the work arrays
 * cannot be allocated: the caller then does every state). The lanes are written and read one
 * double at a time in place (not through a small array copied whole: a vector load from
 * scalar stores just made stalls the CPU's store forwarding, which cost as much as the τ
 * kernel itself). */
static npy_intp in_lanes(const function_t *f, const double *const *in, const double *p,
                         double *out, npy_intp states)
{
    const npy_intp size = (npy_intp)f->rows * (f->cols ? f->cols : 1);
    const size_t slots = (size_t)(MAX_IN * MAX_LEN + NP + 1 + size);
    eom_lanes *work = aligned_alloc(sizeof(eom_lanes), slots * sizeof(eom_lanes));
    eom_lanes *x, *lanes_p, *result;
    const eom_lanes *at[MAX_IN] = {NULL};
    npy_intp k = 0, i;
    int j, l;
    if (work == NULL)
        return 0;
    x = work;
    lanes_p = work + MAX_IN * MAX_LEN;
    result = lanes_p + NP + 1;
    for (i = 0; i < NP + 1; ++i)
        for (l = 0; l < EOM_LANES; ++l)
            EOM_LANE(lanes_p[i], l) = p[i];
    for (j = 0; j < f->n_in; ++j)
        at[j] = x + j * MAX_LEN;
    for (; k + EOM_LANES <= states; k += EOM_LANES) {
        for (j = 0; j < f->n_in; ++j) {
            const npy_intp length = f->sizes[j] ? f->sizes[j] : NV;
            const double *from = in[j] + k * length;
            eom_lanes *to = x + j * MAX_LEN;
            for (l = 0; l < EOM_LANES; ++l)
                for (i = 0; i < length; ++i)
                    EOM_LANE(to[i], l) = from[l * length + i];
        }
        f->lanes(at, lanes_p, result);
        for (l = 0; l < EOM_LANES; ++l)
            for (i = 0; i < size; ++i)
                out[(k + l) * size + i] = EOM_LANE(result[i], l);
    }
    free(work);
    return k;
}

/* The states [begin, end) of a batch: EOM_LANES at a time through f's lanes kernel where it has
 * one (in_lanes), the rest one by one through its one-state kernel. */
static void in_range(const function_t *f, const double *const *in, const double *p,
                     double *out, npy_intp begin, npy_intp end)
{
    const npy_intp size = (npy_intp)f->rows * (f->cols ? f->cols : 1);
    const double *at[MAX_IN] = {NULL};
    npy_intp k = begin;
    int j;
    if (f->lanes != NULL && EOM_LANES > 1) {
        for (j = 0; j < f->n_in; ++j)
            at[j] = in[j] + begin * (f->sizes[j] ? f->sizes[j] : NV);
        k += in_lanes(f, at, p, out + begin * size, end - begin);
    }
    for (; k < end; ++k) {
        for (j = 0; j < f->n_in; ++j)
            at[j] = in[j] + k * (f->sizes[j] ? f->sizes[j] : NV);
        f->kernel(at, p, out + k * size);
    }
}

/* Threads of a batch (docs/backends.md, "Batches on several cores"). A batch is cut into as
 * many contiguous parts as threads, each a whole number of EOM_LANES blocks but the last (which
 * also takes the remainder): state k goes through the same kernel (lanes or one-state) whatever
 * the thread count, so that results are bitwise the same. A batch stays on one thread below
 * EOM_WORK_PER_THREAD arithmetic operations per thread (waking a worker and handing it a part
 * costs microseconds, more on a loaded machine; benchmarks/batch_speed.py times where a second
 * thread pays). The
 * count: set_threads(n), else $EOMGEN_THREADS read at import, else the CPUs this process may
 * run on. Without POSIX threads every batch runs on the calling thread. */
#define EOM_WORK_PER_THREAD 400000L
#define EOM_MAX_THREADS 256
static int eom_threads = 0;  /* 0: the default, eom_default_threads() */
static int eom_threads_at_import = 0;  /* $EOMGEN_THREADS (0: not set) */

static int eom_default_threads(void)
{
#if defined(__linux__) && defined(CPU_COUNT)
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof(set), &set) == 0 && CPU_COUNT(&set) > 0)
        return CPU_COUNT(&set) < EOM_MAX_THREADS ? CPU_COUNT(&set) : EOM_MAX_THREADS;
#endif
#if defined(__unix__) || defined(__APPLE__)
    {
        long online = sysconf(_SC_NPROCESSORS_ONLN);
        if (online > 0)
            return online < EOM_MAX_THREADS ? (int)online : EOM_MAX_THREADS;
    }
#endif
    return 1;
}

/* The threads a batch of `states` runs on, `operations` each (the GIL held: reads the
 * setting); never more than the batch's blocks of EOM_LANES states. A batch too small for two
 * threads (one state above all) returns before asking the system for the CPUs: that call,
 * sched_getaffinity, cost a one-state forward_dynamics 0.8 us, 1.7 times its time. */
static int batch_threads(long operations, npy_intp states)
{
    const double work = (double)states * (double)operations;
    const npy_intp blocks = states / EOM_LANES;
    npy_intp most = (npy_intp)(work / (double)EOM_WORK_PER_THREAD);
    int wanted;
    if (most > blocks)
        most = blocks;
    if (most < 2)
        return 1;
    wanted = eom_threads > 0 ? eom_threads : eom_default_threads();
    return (npy_intp)wanted < most ? wanted : (int)most;
}

/* The work of part `part` of a batch: its states [begin, end). */
typedef void (*range_t)(void *job, int part, npy_intp begin, npy_intp end);

typedef struct {
    range_t run;
    void *job;
    int part;
    npy_intp begin, end;
} part_t;

static void *run_part(void *argument)
{
    const part_t *part = (const part_t *)argument;
    part->run(part->job, part->part, part->begin, part->end);
    return NULL;
}

#if defined(__unix__) || defined(__APPLE__)
/* The module's pool of worker threads, started when a batch first wants them and kept waiting
 * on `wake` between batches. A batch publishes its parts (part 0 is the caller's), each FREE;
 * a worker or the caller takes one by turning it TAKEN (atomically: each part is run once),
 * and marks it DONE. The caller takes the parts no worker has taken, so it never waits for a
 * worker that has not started (a loaded machine, a forked child) but only for the parts being
 * computed; a worker that wakes late finds nothing FREE. One batch at a time (`busy`): another
 * thread's batch meanwhile runs on its own thread. */
enum { PART_FREE, PART_TAKEN, PART_DONE };
static struct {
    pthread_mutex_t busy, lock;
    pthread_cond_t wake;
    unsigned long generation;  /* of the batch published last (lock) */
    int workers, forks_handled;
    part_t parts[EOM_MAX_THREADS];
    int state[EOM_MAX_THREADS];  /* PART_*: atomic */
    int count;                   /* parts of the batch published last (lock) */
} eom_pool = {.busy = PTHREAD_MUTEX_INITIALIZER, .lock = PTHREAD_MUTEX_INITIALIZER,
              .wake = PTHREAD_COND_INITIALIZER};

/* Take and run the FREE parts among 1 .. count - 1, from the first or from the last. */
static void take_parts(int count, int from_last)
{
    int i;
    for (i = 1; i < count; ++i) {
        const int t = from_last ? count - i : i;
        int expected = PART_FREE;
        if (__atomic_compare_exchange_n(&eom_pool.state[t], &expected, PART_TAKEN, 0,
                                        __ATOMIC_ACQ_REL, __ATOMIC_ACQUIRE)) {
            run_part(&eom_pool.parts[t]);
            __atomic_store_n(&eom_pool.state[t], PART_DONE, __ATOMIC_RELEASE);
        }
    }
}

static void *pool_worker(void *unused)
{
    unsigned long seen;
    (void)unused;
    pthread_mutex_lock(&eom_pool.lock);
    seen = eom_pool.generation;
    for (;;) {
        int count;
        while (eom_pool.generation == seen)
            pthread_cond_wait(&eom_pool.wake, &eom_pool.lock);
        seen = eom_pool.generation;
        count = eom_pool.count;
        pthread_mutex_unlock(&eom_pool.lock);
        take_parts(count, 0);
        pthread_mutex_lock(&eom_pool.lock);
    }
    return NULL;
}

/* In a child process after fork(): no worker exists there; a fresh pool. */
static void pool_after_fork(void)
{
    pthread_mutex_init(&eom_pool.busy, NULL);
    pthread_mutex_init(&eom_pool.lock, NULL);
    pthread_cond_init(&eom_pool.wake, NULL);
    eom_pool.workers = 0;
}

/* Start workers until there are `wanted` (fewer when a thread cannot be started). */
static void pool_start(int wanted)
{
    pthread_attr_t attributes;
    if (!eom_pool.forks_handled)
        eom_pool.forks_handled = pthread_atfork(NULL, NULL, pool_after_fork) == 0;
    if (eom_pool.workers >= wanted || pthread_attr_init(&attributes) != 0)
        return;
    pthread_attr_setdetachstate(&attributes, PTHREAD_CREATE_DETACHED);
    while (eom_pool.workers < wanted) {
        pthread_t id;
        if (pthread_create(&id, &attributes, pool_worker, NULL) != 0)
            break;
        ++eom_pool.workers;
    }
    pthread_attr_destroy(&attributes);
}
#endif

/* run(job, t, ...) on the batch's states in `parts` contiguous parts on `threads` threads:
 * EOM_PARTS_PER_THREAD parts a thread (at most EOM_MAX_THREADS, at least a block each), part t
 * from state blocks * t / parts * EOM_LANES (blocks: whole blocks of EOM_LANES states), the last
 * taking the remainder. Part 0 on the calling thread, the others on the pool's workers or, those
 * no worker took, on the calling thread too: the parts are the same whoever computes them, and
 * a worker that loses its core holds up the batch by one small part at most. Returns the number
 * of parts, 1 (the whole batch as part 0) when the pool is busy with another batch or there are
 * no POSIX threads. */
#define EOM_PARTS_PER_THREAD 8
static int in_parts(range_t run, void *job, npy_intp states, int threads)
{
    part_t whole;
#if defined(__unix__) || defined(__APPLE__)
    if (threads > 1 && pthread_mutex_trylock(&eom_pool.busy) == 0) {
        const npy_intp blocks = states / EOM_LANES;
        part_t *parts = eom_pool.parts;
        npy_intp most = (npy_intp)threads * EOM_PARTS_PER_THREAD;
        int count, t;
        if (most > EOM_MAX_THREADS)
            most = EOM_MAX_THREADS;
        count = (int)(most < blocks ? most : blocks);
        pool_start(threads - 1);
        for (t = 0; t < count; ++t) {
            parts[t].run = run;
            parts[t].job = job;
            parts[t].part = t;
            parts[t].begin = blocks * t / count * EOM_LANES;
            parts[t].end = t + 1 < count ? blocks * (t + 1) / count * EOM_LANES : states;
            __atomic_store_n(&eom_pool.state[t], t ? PART_FREE : PART_TAKEN, __ATOMIC_RELEASE);
        }
        pthread_mutex_lock(&eom_pool.lock);
        eom_pool.count = count;
        ++eom_pool.generation;
        pthread_cond_broadcast(&eom_pool.wake);
        pthread_mutex_unlock(&eom_pool.lock);
        run_part(&parts[0]);
        take_parts(count, 0);
        for (t = 1; t < count; ++t)
            while (__atomic_load_n(&eom_pool.state[t], __ATOMIC_ACQUIRE) != PART_DONE)
                sched_yield();
        pthread_mutex_unlock(&eom_pool.busy);
        return count;
    }
#endif
    whole.run = run;
    whole.job = job;
    whole.part = 0;
    whole.begin = 0;
    whole.end = states;
    run_part(&whole);
    return 1;
}

/* evaluate()'s batch: f on inputs `in`, parameters p, results `out`. */
typedef struct {
    const function_t *f;
    const double *const *in;
    const double *p;
    double *out;
} evaluation_t;

static void evaluate_range(void *job, int part, npy_intp begin, npy_intp end)
{
    const evaluation_t *e = (const evaluation_t *)job;
    (void)part;
    in_range(e->f, e->in, e->p, e->out, begin, end);
}

/* Module functions set_threads(n) and threads(). */
static PyObject *set_threads(PyObject *self, PyObject *value)
{
    long n;
    (void)self;
    if (value == Py_None) {
        eom_threads = eom_threads_at_import;
        Py_RETURN_NONE;
    }
    n = PyLong_Check(value) ? PyLong_AsLong(value) : -1;
    if (n == -1 && PyErr_Occurred())
        PyErr_Clear();
    if (!PyLong_Check(value) || PyBool_Check(value) || n < 1 || n > EOM_MAX_THREADS) {
        PyErr_Format(PyLong_Check(value) && !PyBool_Check(value) ? PyExc_ValueError
                                                                 : PyExc_TypeError,
                     "set_threads(): n must be an integer from 1 to %d or None (the CPUs this "
                     "process may use), got %R", EOM_MAX_THREADS, value);
        return NULL;
    }
    eom_threads = (int)n;
    Py_RETURN_NONE;
}

static PyObject *threads(PyObject *self, PyObject *unused)
{
    (void)self;
    (void)unused;
    return PyLong_FromLong(eom_threads > 0 ? eom_threads : eom_default_threads());
}

/* At import: $EOMGEN_THREADS, when set, is the thread count; -1 with a ValueError when it is
 * not an integer from 1 to EOM_MAX_THREADS. */
static int read_threads_variable(void)
{
    const char *text = getenv("EOMGEN_THREADS");
    char *end = NULL;
    long n;
    if (text == NULL || *text == '\0')
        return 0;
    n = strtol(text, &end, 10);
    if (*end != '\0' || n < 1 || n > EOM_MAX_THREADS) {
        PyErr_Format(PyExc_ValueError, "EOMGEN_THREADS must be an integer from 1 to %d, got "
                     "'%s'", EOM_MAX_THREADS, text);
        return -1;
    }
    eom_threads = eom_threads_at_import = (int)n;
    return 0;
}

#define THREAD_METHODS \
    {"set_threads", (PyCFunction)set_threads, METH_O, \
     "set_threads(n)\n--\n\nRun this module's batches on n threads (n from 1 to 256; None: the " \
     "CPUs this process may use, or $EOMGEN_THREADS when set at import). Batches of little " \
     "work stay on one thread; results are bitwise the same for every n."}, \
    {"threads", (PyCFunction)threads, METH_NOARGS, \
     "threads()\n--\n\nThe number of threads this module's batches may run on."}

/* The keywords a composed function takes besides its inputs and parameters (parse()). */
#define TAKES_RETURN_CONDITION 1
#define TAKES_DAMPING 2

static void release(call_t *call)
{
    int i;
    for (i = 0; i < MAX_IN; ++i)
        Py_CLEAR(call->arrays[i]);
}

/* The type (TypeError) and value (FloatingPointError) errors of an input: the eomgen rule for
 * every function of the NumPy and fast modules (docs/backends.md, "Values a function refuses").
 * refuse_type: the input `name` does not hold real numbers (complex, text, ...). */
static void refuse_type(const function_t *f, PyObject *object, const char *name)
{
    PyObject *array = PyArray_FROM_O(object), *dtype = NULL;
    PyErr_Clear();
    if (array != NULL)
        dtype = PyObject_GetAttrString(array, "dtype");
    PyErr_Clear();
    if (dtype != NULL)
        PyErr_Format(PyExc_TypeError, "%s: %s must hold real numbers, got dtype %S", f->name,
                     name, dtype);
    else
        PyErr_Format(PyExc_TypeError, "%s: %s must hold real numbers, got %R", f->name, name,
                     object);
    Py_XDECREF(dtype);
    Py_XDECREF(array);
}

/* The words for a value that is not finite: "nan", "inf" or "-inf", as Python prints them. */
static const char *not_finite(double value)
{
    return isnan(value) ? "nan" : value > 0 ? "inf" : "-inf";
}

/* 0 when the `count` values (`size` a state) are finite, else -1 with a FloatingPointError
 * naming the input, its first bad entry and (batch) its state. One pass of integer arithmetic
 * the compiler makes SIMD, without a branch: a double is nan or +-inf when its exponent bits
 * are all ones, and only then does adding one to the exponent field carry into bit 63. */
static int check_finite(const function_t *f, const double *x, npy_intp count, int size,
                        int batch, const char *name)
{
    unsigned long long carried = 0, bits;
    npy_intp i;
    for (i = 0; i < count; ++i) {
        memcpy(&bits, &x[i], sizeof bits);
        carried |= (bits & 0x7ff0000000000000ULL) + 0x0010000000000000ULL;
    }
    if (!(carried >> 63))
        return 0;
    for (i = 0; isfinite(x[i]); ++i)
        ;
    if (batch)
        PyErr_Format(PyExc_FloatingPointError, "%s: %s is not finite at state %zd: entry %d "
                     "is %s", f->name, name, (Py_ssize_t)(i / size), (int)(i % size),
                     not_finite(x[i]));
    else
        PyErr_Format(PyExc_FloatingPointError, "%s: %s is not finite: entry %d is %s", f->name,
                     name, (int)i, not_finite(x[i]));
    return -1;
}

static PyArrayObject *as_states(const function_t *f, PyObject *object, const char *name,
                                int size)
{
    PyArrayObject *array;
    if (PyArray_CheckExact(object) && PyArray_TYPE((PyArrayObject *)object) == NPY_DOUBLE &&
            PyArray_ISCARRAY_RO((PyArrayObject *)object)) {
        Py_INCREF(object);
        array = (PyArrayObject *)object;
    } else {
        array = (PyArrayObject *)PyArray_FROMANY(object, NPY_DOUBLE, 0, 0, NPY_ARRAY_IN_ARRAY);
        if (array == NULL) {
            if (PyErr_ExceptionMatches(PyExc_TypeError) ||
                    PyErr_ExceptionMatches(PyExc_ValueError))
                refuse_type(f, object, name);
            return NULL;
        }
    }
    if (!((PyArray_NDIM(array) == 1 && PyArray_DIM(array, 0) == size) ||
          (PyArray_NDIM(array) == 2 && PyArray_DIM(array, 1) == size))) {
        PyObject *shape = PyObject_GetAttrString((PyObject *)array, "shape");
        PyErr_Format(PyExc_ValueError, "%s must have shape (%d,) or (N, %d), got %R", name, size,
                     size, shape);
        Py_XDECREF(shape);
        Py_DECREF(array);
        return NULL;
    }
    if (check_finite(f, (const double *)PyArray_DATA(array), PyArray_SIZE(array), size,
                     PyArray_NDIM(array) == 2, name) < 0) {
        Py_DECREF(array);
        return NULL;
    }
    return array;
}

/* A keyword's number: -1 with a TypeError naming f and the keyword (`what`: "parameter 'm1'",
 * "damping") when value is no real number (text, complex, an array of several ...). */
static int keyword_number(const function_t *f, PyObject *value, const char *what, double *out)
{
    const int refused = PyComplex_Check(value) || PyUnicode_Check(value) ||
        PyBytes_Check(value) || PyArray_IsScalar(value, ComplexFloating) ||
        (PyArray_Check(value) && PyArray_ISCOMPLEX((PyArrayObject *)value));
    *out = refused ? -1.0 : PyFloat_AsDouble(value);
    if (refused || (*out == -1.0 && PyErr_Occurred())) {
        PyErr_Clear();
        PyErr_Format(PyExc_TypeError, "%s(): %s must be a real number, got %R", f->name, what,
                     value);
        return -1;
    }
    return 0;
}

static int parse(const function_t *f, PyObject *const *args, Py_ssize_t nargs,
                 PyObject *kwnames, call_t *call, int takes)
{
    PyObject *given[MAX_IN] = {NULL};
    int set[NP + 1] = {0};
    Py_ssize_t i, nkw = kwnames ? PyTuple_GET_SIZE(kwnames) : 0;
    int j;
    memset(call, 0, sizeof(*call));
    if (nargs > f->n_in) {
        PyErr_Format(PyExc_TypeError, "%s() takes %d positional arguments but %zd were given",
                     f->name, f->n_in, nargs);
        return -1;
    }
    for (i = 0; i < nargs; ++i)
        given[i] = args[i];
    for (i = 0; i < nkw; ++i) {
        PyObject *key = PyTuple_GET_ITEM(kwnames, i), *value = args[nargs + i];
        int found = 0;
        for (j = 0; j < f->n_in && !found; ++j)
            if (PyUnicode_CompareWithASCIIString(key, f->inputs[j]) == 0) {
                if (given[j] != NULL) {
                    PyErr_Format(PyExc_TypeError, "%s() got multiple values for argument '%s'",
                                 f->name, f->inputs[j]);
                    return -1;
                }
                given[j] = value;
                found = 1;
            }
        for (j = 0; j < NP && !found; ++j)
            if (PyUnicode_CompareWithASCIIString(key, parameter_names[j]) == 0) {
                char what[160];
                snprintf(what, sizeof what, "parameter '%s'", parameter_names[j]);
                if (keyword_number(f, value, what, &call->p[j]) < 0)
                    return -1;
                if (!isfinite(call->p[j])) {
                    PyErr_Format(PyExc_FloatingPointError, "%s(): %s is not finite: %s",
                                 f->name, what, not_finite(call->p[j]));
                    return -1;
                }
                set[j] = 1;
                found = 1;
            }
        if (!found && (takes & TAKES_RETURN_CONDITION) &&
                PyUnicode_CompareWithASCIIString(key, "return_condition") == 0) {
            int truth = PyObject_IsTrue(value);
            if (truth < 0)
                return -1;
            call->return_condition = truth;
            found = 1;
        }
        if (!found && (takes & TAKES_DAMPING) &&
                PyUnicode_CompareWithASCIIString(key, "damping") == 0) {
            if (keyword_number(f, value, "damping", &call->damping) < 0)
                return -1;
            if (!(call->damping >= 0.0 && isfinite(call->damping))) {
                PyErr_Format(PyExc_ValueError, "%s(): damping must be a finite number >= 0, "
                             "got %R", f->name, value);
                return -1;
            }
            found = 1;
        }
        if (!found) {
            const char *text = PyUnicode_AsUTF8(key);
            if (text == NULL)
                return -1;
            for (j = 0; renamed_parameters[j][0] != NULL; ++j)
                if (strcmp(text, renamed_parameters[j][0]) == 0) {
                    PyErr_Format(PyExc_TypeError, "%s() got an unexpected keyword argument %R: "
                                 "parameter %R of the description is the keyword '%s'",
                                 f->name, key, key, renamed_parameters[j][1]);
                    return -1;
                }
            PyErr_Format(PyExc_TypeError, "%s() got an unexpected keyword argument %R",
                         f->name, key);
            return -1;
        }
    }
    for (j = 0; j < NP; ++j)
        if (!set[j]) {
            if (!parameter_has_default[j]) {
                PyErr_Format(PyExc_TypeError,
                             "%s() missing keyword argument '%s' (the description gives it no "
                             "value)", f->name, parameter_names[j]);
                return -1;
            }
            call->p[j] = parameter_defaults[j];
        }
    call->single = 1;
    call->states = 1;  /* a function without vector inputs is evaluated once */
    for (j = 0; j < f->n_in; ++j) {
        if (given[j] == NULL) {
            PyErr_Format(PyExc_TypeError, "%s() missing required argument '%s'", f->name,
                         f->inputs[j]);
            release(call);
            return -1;
        }
        call->arrays[j] = as_states(f, given[j], f->inputs[j], f->sizes[j] ? f->sizes[j] : NV);
        if (call->arrays[j] == NULL) {
            release(call);
            return -1;
        }
        {
            int one = PyArray_NDIM(call->arrays[j]) == 1;
            npy_intp states = one ? 1 : PyArray_DIM(call->arrays[j], 0);
            if (j > 0 && states != call->states) {
                PyErr_Format(PyExc_ValueError, "the inputs must hold the same number of "
                             "states, got %zd (%s) and %zd (%s)", (Py_ssize_t)call->states,
                             f->inputs[0], (Py_ssize_t)states, f->inputs[j]);
                release(call);
                return -1;
            }
            call->states = states;
            call->single = call->single && one;
        }
    }
    return 0;
}

static PyObject *evaluate(const function_t *f, PyObject *const *args, Py_ssize_t nargs,
                          PyObject *kwnames)
{
    call_t call;
    npy_intp dims[3];
    int nd = 0, j;
    const double *in[MAX_IN] = {NULL};
    double *out;
    PyArrayObject *result;
    if (parse(f, args, nargs, kwnames, &call, 0) < 0)
        return NULL;
    if (!call.single)
        dims[nd++] = call.states;
    dims[nd++] = f->rows;
    if (f->cols)
        dims[nd++] = f->cols;
    result = (PyArrayObject *)PyArray_SimpleNew(nd, dims, NPY_DOUBLE);
    if (result == NULL) {
        release(&call);
        return NULL;
    }
    out = (double *)PyArray_DATA(result);
    for (j = 0; j < f->n_in; ++j)
        in[j] = (const double *)PyArray_DATA(call.arrays[j]);
    if (call.states == 1) {
        f->kernel(in, call.p, out);
    } else {
        evaluation_t job = {f, in, call.p, out};
        const int threads = batch_threads(f->operations, call.states);
        Py_BEGIN_ALLOW_THREADS
        in_parts(evaluate_range, &job, call.states, threads);
        Py_END_ALLOW_THREADS
    }
    release(&call);
    return (PyObject *)result;
}
