/* Runtime of eomgen's fast backend: the Python call of the constrained forward dynamics (a
 * generated `_fast.c` exporting it includes this after the call runtime, call.c): its
 * arguments parsed, the states solved one by one, the errors raised by status.
 *
 * Real C source, not a template: eomgen copies the text below the marker line into the module
 * (eomgen.codegen.backends.fast_backend.runtime_source), and tests/test_fast_runtime_c.py
 * compiles it on its own with -Wall -Wextra -Werror (after what the module defines before the
 * call runtime: NV, NP, MAX_IN and the parameter tables). */
#include "call.c"  /* compiled alone: the call parsing it uses */

/* eomgen: the generated module holds the text below this line. */
/* The kernel of one state of the constrained forward dynamics (see constrained_solve): qdd
 * (NV) and the contact forces F (nc) at (q, qd, tau), parameters p; returns the status. */
typedef int (*contact_kernel_t)(const double *, const double *, const double *, const double *,
                                double, double *, double *);

/* The function f (inputs q, qd, tau; keyword damping) called from Python: (qdd, F_c) of
 * shapes (NV,), (nc,) for one state, (N, NV), (N, nc) for a batch, solved state by state with
 * `one`; FloatingPointError or numpy.linalg.LinAlgError named after f at the first state that
 * fails. `messages` (or NULL for the contact ones): what status 1 (not finite) and status 3
 * (singular at damping 0) say, for another function solved alike (the parallel inverse
 * dynamics: inputs q, qd, qdd; results tau, lambda). */
static PyObject *contact_call(const function_t *f, contact_kernel_t one, int nc,
                              const char *const *messages, PyObject *const *args,
                              Py_ssize_t nargs, PyObject *kwnames)
{
    call_t call;
    npy_intp dims[2], k, failed = -1;
    int status = 0;
    const double *q, *qd, *tau;
    double *qdd, *F;
    PyArrayObject *result, *forces;
    if (parse(f, args, nargs, kwnames, &call, TAKES_DAMPING) < 0)
        return NULL;
    dims[0] = call.states;
    dims[1] = NV;
    result = (PyArrayObject *)(call.single ? PyArray_SimpleNew(1, dims + 1, NPY_DOUBLE)
                                           : PyArray_SimpleNew(2, dims, NPY_DOUBLE));
    dims[1] = nc;
    forces = (PyArrayObject *)(call.single ? PyArray_SimpleNew(1, dims + 1, NPY_DOUBLE)
                                           : PyArray_SimpleNew(2, dims, NPY_DOUBLE));
    if (result == NULL || forces == NULL) {
        Py_XDECREF(result);
        Py_XDECREF(forces);
        release(&call);
        return NULL;
    }
    q = (const double *)PyArray_DATA(call.arrays[0]);
    qd = (const double *)PyArray_DATA(call.arrays[1]);
    tau = (const double *)PyArray_DATA(call.arrays[2]);
    qdd = (double *)PyArray_DATA(result);
    F = (double *)PyArray_DATA(forces);
    for (k = 0; k < call.states; ++k) {
        status = one(q + k * NQ, qd + k * NV, tau + k * NV, call.p, call.damping, qdd + k * NV,
                     F + k * nc);
        if (status) {
            failed = k;
            break;
        }
    }
    release(&call);
    if (failed >= 0) {
        char at[64] = "";
        if (!call.single)
            PyOS_snprintf(at, sizeof(at), " at state %zd", (Py_ssize_t)failed);
        if (messages != NULL && status == 1)
            PyErr_Format(PyExc_FloatingPointError, "%s: %s%s", f->name, messages[0], at);
        else if (messages != NULL && status == 3 && !(call.damping > 0.0))
            PyErr_Format(lin_alg_error, "%s: %s%s; use damping > 0", f->name, messages[1], at);
        else if (status == 1)
            PyErr_Format(PyExc_FloatingPointError, "%s: M(q), C(q, qd) qd + g(q), tau, J_c(q) "
                         "or J_c-dot qd is not finite%s (overflow, or non-finite input)",
                         f->name, at);
        else if (status == 2)
            PyErr_Format(lin_alg_error, "%s: M(q) is not positive definite%s: a joint moves no "
                         "mass or inertia, or the inertias are not physical", f->name, at);
        else if (call.damping > 0.0)
            PyErr_Format(lin_alg_error, "%s: J_c M^-1 J_c^T + damping 1 is not positive "
                         "definite%s (damping %g is lost in rounding)", f->name, at,
                         call.damping);
        else
            PyErr_Format(lin_alg_error, "%s: the contact Jacobian (%dx%d) has dependent rows%s: "
                         "J_c M^-1 J_c^T is singular (cond >~ 1e10) and the contact forces are "
                         "not unique (redundant contacts, or a direction no joint moves a "
                         "contact frame in); use damping > 0", f->name, nc, NV, at);
        Py_DECREF(result);
        Py_DECREF(forces);
        return NULL;
    }
    return Py_BuildValue("(NN)", result, forces);
}
