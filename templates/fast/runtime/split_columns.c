/* Runtime of eomgen's fast backend: the split of a several-result function's side-by-side
 * output into the tuple of its results (included in a generated `_fast.c` that exports such a
 * function, e.g. mass_and_bias). Needs only Python.h.
 *
 * Real C source, not a template: eomgen copies the text below the marker line into the module
 * (eomgen.codegen.backends.fast_backend.runtime_source), and tests/test_fast_runtime_c.py
 * compiles it on its own with -Wall -Wextra -Werror. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

/* eomgen: the generated module holds the text below this line. */
/* A several-result function's side-by-side matrix `full` ((n, width) or (N, n, width)) split
 * into the tuple of its results: full[..., start:stop] for a matrix, full[..., start] for a
 * vector (stop < 0). Steals the reference to `full`. */
static PyObject *split_columns(PyObject *full, int count, const int *start, const int *stop)
{
    PyObject *result, *index, *part;
    int k;
    if (full == NULL)
        return NULL;
    result = PyTuple_New(count);
    for (k = 0; result != NULL && k < count; ++k) {
        PyObject *column = PyLong_FromLong(start[k]);
        if (column != NULL && stop[k] >= 0) {
            PyObject *end = PyLong_FromLong(stop[k]);
            PyObject *slice = end ? PySlice_New(column, end, NULL) : NULL;
            Py_XDECREF(end);
            Py_DECREF(column);
            column = slice;
        }
        index = column ? PyTuple_Pack(2, Py_Ellipsis, column) : NULL;
        Py_XDECREF(column);
        part = index ? PyObject_GetItem(full, index) : NULL;
        Py_XDECREF(index);
        if (part == NULL)
            Py_CLEAR(result);
        else
            PyTuple_SET_ITEM(result, k, part);
    }
    Py_DECREF(full);
    return result;
}
