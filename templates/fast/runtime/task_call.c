/* Runtime of eomgen's fast backend: the Python call of the task-space functions (a generated
 * `_fast.c` exporting one includes this after the call runtime, call.c): the keywords linear
 * and frames taken out, the rest parsed as every function's (damping too), the states solved
 * one by one, the errors raised by status; the NumPy module's shapes and messages.
 *
 * Real C source, not a template: eomgen copies the text below the marker line into the module
 * (eomgen.codegen.backends.fast_backend.runtime_source), and tests/test_fast_runtime_c.py
 * compiles it on its own with -Wall -Wextra -Werror (after what the module defines before the
 * call runtime: NV, NP, MAX_IN and the parameter tables). */
#include "call.c"  /* compiled alone: the call parsing it uses */

/* eomgen: the generated module holds the text below this line. */
/* What a task-space function returns, per frame: Lambda (r x r), (mu, p) (r each), Jbar
 * (NV x r). */
#define TASK_INERTIA 0
#define TASK_BIAS 1
#define TASK_INVERSE 2

/* The kernel of one state: at (q, qd) (qd NULL but for the bias), parameters p, the results
 * of `kind` for the nsel frames of indices frames[], r rows each (6, or 3: the linear rows), at
 * out (and out2: p of the bias). Returns 0, 1 when an input of the solve is not finite, 2 when
 * M is not positive definite, 3 when J M^-1 J^T (+ damping 1) of frame number *bad is not. */
typedef int (*task_kernel_t)(const double *, const double *, const double *, double, int, int,
                             const int *, int, double *, double *, int *);

/* The index of frame `o` (a name of names[0..nf-1] or an index, negative from the end) in
 * *index; -1 with an exception set when there is no such frame. */
static int frame_index(PyObject *o, int nf, const char *const *names, const char *who,
                       int *index)
{
    int i;
    if (PyUnicode_Check(o)) {
        for (i = 0; i < nf; ++i)
            if (PyUnicode_CompareWithASCIIString(o, names[i]) == 0) {
                *index = i;
                return 0;
            }
        PyErr_Format(PyExc_ValueError, "%s: unknown frame %R (see FRAME_NAMES)", who, o);
        return -1;
    }
    if (PyIndex_Check(o)) {
        Py_ssize_t k = PyNumber_AsSsize_t(o, PyExc_IndexError);
        if (k == -1 && PyErr_Occurred())
            return -1;
        if (k < -nf || k >= nf) {
            PyErr_Format(PyExc_ValueError, "%s: frame index %zd out of range for %d frames", who,
                         k, nf);
            return -1;
        }
        *index = (int)(k < 0 ? k + nf : k);
        return 0;
    }
    PyErr_Format(PyExc_TypeError, "%s: a frame is a name of FRAME_NAMES or an index, got %R",
                 who, o);
    return -1;
}

/* The function f (inputs q, or q and qd for the bias; keywords damping, linear, frames and the
 * parameters) called from Python with the kernel `one` over the module's nf frames `names`. */
static PyObject *task_call(const function_t *f, task_kernel_t one, int kind, int nf,
                           const char *const *names, PyObject *const *args, Py_ssize_t nargs,
                           PyObject *kwnames)
{
    Py_ssize_t nkw = kwnames ? PyTuple_GET_SIZE(kwnames) : 0, i, nkept = 0;
    PyObject **kept = PyMem_Malloc(sizeof(PyObject *) * (size_t)(nargs + nkw + 1));
    PyObject *kept_names = PyList_New(0), *keywords = NULL, *linear_obj = NULL;
    PyObject *frames_obj = NULL, *sequence = NULL, *out = NULL, *out2 = NULL, *result = NULL;
    int *frames = NULL, r = 6, single_frame = 0, nsel = 0, status = 0, bad = 0, nd = 0, parsed = 0;
    npy_intp dims[4], k, failed = -1, per;
    call_t call;
    if (kept == NULL || kept_names == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    for (i = 0; i < nargs; ++i)
        kept[i] = args[i];
    for (i = 0; i < nkw; ++i) {
        PyObject *key = PyTuple_GET_ITEM(kwnames, i);
        if (PyUnicode_CompareWithASCIIString(key, "linear") == 0)
            linear_obj = args[nargs + i];
        else if (PyUnicode_CompareWithASCIIString(key, "frames") == 0)
            frames_obj = args[nargs + i];
        else {
            kept[nargs + nkept++] = args[nargs + i];
            if (PyList_Append(kept_names, key) < 0)
                goto done;
        }
    }
    if (nkept && (keywords = PyList_AsTuple(kept_names)) == NULL)
        goto done;
    if (linear_obj != NULL) {
        int truth = PyObject_IsTrue(linear_obj);
        if (truth < 0)
            goto done;
        r = truth ? 3 : 6;
    }
    if (frames_obj == NULL || frames_obj == Py_None) {
        nsel = nf;
    } else if (PyUnicode_Check(frames_obj) || PyIndex_Check(frames_obj)) {
        nsel = 1;
        single_frame = 1;
    } else {
        sequence = PySequence_Fast(frames_obj, "frames must be None, a frame name or index, "
                                   "or a sequence of them");
        if (sequence == NULL)
            goto done;
        nsel = (int)PySequence_Fast_GET_SIZE(sequence);
    }
    frames = PyMem_Malloc(sizeof(int) * (size_t)(nsel + 1));
    if (frames == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    for (i = 0; i < nsel; ++i) {
        if (sequence != NULL) {
            if (frame_index(PySequence_Fast_GET_ITEM(sequence, i), nf, names, f->name,
                            frames + i) < 0)
                goto done;
        } else if (single_frame) {
            if (frame_index(frames_obj, nf, names, f->name, frames + i) < 0)
                goto done;
        } else {
            frames[i] = (int)i;
        }
    }
    if (parse(f, kept, nargs, keywords, &call, TAKES_DAMPING) < 0)
        goto done;
    parsed = 1;
    if (!call.single)
        dims[nd++] = call.states;
    if (!single_frame)
        dims[nd++] = nsel;
    dims[nd++] = kind == TASK_INVERSE ? NV : r;
    if (kind == TASK_INERTIA || kind == TASK_INVERSE)
        dims[nd++] = r;
    per = (npy_intp)nsel * r * (kind == TASK_INERTIA ? r : kind == TASK_INVERSE ? NV : 1);
    out = PyArray_SimpleNew(nd, dims, NPY_DOUBLE);
    if (out == NULL || (kind == TASK_BIAS && (out2 = PyArray_SimpleNew(nd, dims,
                                                                       NPY_DOUBLE)) == NULL))
        goto done;
    {
        const double *q = (const double *)PyArray_DATA(call.arrays[0]);
        const double *qd = kind == TASK_BIAS ? (const double *)PyArray_DATA(call.arrays[1])
                                             : NULL;
        double *o = (double *)PyArray_DATA((PyArrayObject *)out);
        double *o2 = out2 ? (double *)PyArray_DATA((PyArrayObject *)out2) : NULL;
        for (k = 0; k < call.states; ++k) {
            status = one(q + k * NQ, qd ? qd + k * NV : NULL, call.p, call.damping, kind, r,
                         frames, nsel, o + k * per, o2 ? o2 + k * per : NULL, &bad);
            if (status) {
                failed = k;
                break;
            }
        }
    }
    if (failed >= 0) {
        char at[64] = "";
        if (!call.single)
            PyOS_snprintf(at, sizeof(at), " at state %zd", (Py_ssize_t)failed);
        if (status == 1)
            PyErr_Format(PyExc_FloatingPointError, "%s: M(q), a frame Jacobian, C qd + g or "
                         "Jdot qd is not finite%s (overflow, or non-finite input)", f->name, at);
        else if (status == 2)
            PyErr_Format(lin_alg_error, "%s: M(q) is not positive definite%s: a joint moves no "
                         "mass or inertia, or the inertias are not physical", f->name, at);
        else if (call.damping > 0.0)
            PyErr_Format(lin_alg_error, "%s: J M^-1 J^T + damping 1 is not positive "
                         "definite%s (damping %g is lost in rounding); use a larger damping",
                         f->name, at, call.damping);
        else
            PyErr_Format(lin_alg_error, "%s: J M^-1 J^T of frame '%s' (%dx%d) is singular%s (a "
                         "Cholesky pivot <= 1e-10 of its largest diagonal entry, cond >~ 1e10: "
                         "a kinematic singularity, or a direction no joint moves the frame in); "
                         "use damping > 0", f->name, names[frames[bad]], r, r, at);
        goto done;
    }
    if (kind == TASK_BIAS) {
        result = Py_BuildValue("(OO)", out, out2);
    } else {
        result = out;
        Py_INCREF(result);
    }
done:
    if (parsed)
        release(&call);
    Py_XDECREF(out);
    Py_XDECREF(out2);
    Py_XDECREF(sequence);
    Py_XDECREF(keywords);
    Py_XDECREF(kept_names);
    PyMem_Free(frames);
    PyMem_Free(kept);
    return result;
}
