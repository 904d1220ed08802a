/* Compiled kernels, each making the numba kernel's choices:
 *
 *   lemke(M, q, d, max_pivots, tol, z, basis) -> (status, pivots)
 *       Lemke's method with lexicographic anti-cycling, solvers/numerics/lemke.py's numba kernel
 *       pivot for pivot. M: (n, n) float64, q and d: (n,) float64; z: (n,) float64 and basis: (n,)
 *       int64 are filled. NaN never qualifies in a comparison, so NaN data end on a ray or at
 *       max_pivots, never in a loop or out of bounds.
 *   lemke_address
 *       The address of quasistatic_lemke, the same method on raw pointers (no Python objects):
 *       the numba install's kernels call it from compiled code.
 *   fixed_mode_system(J, b, mu, g, x, kind, column, residual, jacobian, forces) -> None
 *       The fixed-mode laws at x, laws/fixed_modes.py::system loop for loop (the 3-D fast
 *       path's Newton iterations call it); the last three arrays are filled.
 *
 * Written against the Python C API only (buffers in and out, every one C-contiguous, no numpy
 * headers), so setuptools alone builds it; quasistatic/compiled.py wraps it. Shapes and indices
 * are checked (ValueError); the GIL is released while it computes.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { SOLUTION = 0, RAY = 1, PIVOT_LIMIT = 2 };

/* One run's state: B^-1 column-major (each step below is a loop down contiguous columns,
 * which the compiler vectorizes), the basic values, the entering column, the basis, and
 * the candidate rows of the ratio test with their values. */
typedef struct {
    Py_ssize_t n;
    const double *M, *q, *d;
    double *Binv, *xB, *col, *values;
    int64_t *basis, *rows;
} Lemke;

/* Eliminate the entering column on `row`, in the kernel's arithmetic: the pivot row times the
 * reciprocal of the pivot, then every row minus its factor (the column, 0 on `row`) times it. */
static void pivot(Lemke *s, int64_t row) {
    const Py_ssize_t n = s->n;
    const double scale = 1.0 / s->col[row];
    double *restrict factors = s->col; /* the column is not needed after this pivot */
    factors[row] = 0.0;
    for (Py_ssize_t j = 0; j < n; j++) {
        double *restrict column = s->Binv + j * n;
        const double value = column[row] * scale;
        for (Py_ssize_t i = 0; i < n; i++) column[i] -= factors[i] * value;
        column[row] = value;
    }
    const double value = s->xB[row] * scale;
    for (Py_ssize_t i = 0; i < n; i++) s->xB[i] -= factors[i] * value;
    s->xB[row] = value;
}

/* B^-1 A_e for the entering variable's column A_e of [I, -M, -d]: each entry summed over j in
 * order, as a dot product of a row of B^-1 would be, then negated for -M and -d. */
static void entering_column(Lemke *s, int64_t entering) {
    const Py_ssize_t n = s->n;
    double *restrict col = s->col;
    if (entering < n) {
        for (Py_ssize_t i = 0; i < n; i++) col[i] = s->Binv[entering * n + i];
        return;
    }
    for (Py_ssize_t i = 0; i < n; i++) col[i] = 0.0;
    for (Py_ssize_t j = 0; j < n; j++) {
        const double a = entering < 2 * n ? s->M[j * n + (entering - n)] : s->d[j];
        const double *restrict column = s->Binv + j * n;
        for (Py_ssize_t i = 0; i < n; i++) col[i] += column[i] * a;
    }
    for (Py_ssize_t i = 0; i < n; i++) col[i] = -col[i];
}

/* Keep the candidate rows whose value (x_B, or column `column` of B^-1, over the entering
 * column) is within the tie width of the smallest: tol * (1 + |smallest|) for the ratios,
 * tol for a column of B^-1. The order of the rows is kept. When every value is NaN
 * nothing qualifies and the rows stay as they were; returns the number kept, 0 then. */
static Py_ssize_t keep_smallest(Lemke *s, Py_ssize_t count, Py_ssize_t column, double tol) {
    const Py_ssize_t n = s->n;
    double smallest = INFINITY;
    for (Py_ssize_t k = 0; k < count; k++) {
        const int64_t i = s->rows[k];
        s->values[k] = (column < 0 ? s->xB[i] : s->Binv[column * n + i]) / s->col[i];
        if (s->values[k] < smallest) smallest = s->values[k];
    }
    const double width = column < 0 ? tol * (1.0 + fabs(smallest)) : tol;
    Py_ssize_t kept = 0;
    for (Py_ssize_t k = 0; k < count; k++)
        if (s->values[k] <= smallest + width) s->rows[kept++] = s->rows[k];
    return kept;
}

/* The leaving row by the lexicographic minimum ratio; -1 when no entry of the entering
 * column is above the pivot tolerance (relative to its largest magnitude). */
static int64_t ratio_test(Lemke *s, int64_t artificial, double tol) {
    const Py_ssize_t n = s->n;
    double largest = 1.0;
    for (Py_ssize_t i = 0; i < n; i++)
        if (fabs(s->col[i]) > largest) largest = fabs(s->col[i]);
    const double pivot_tol = tol * largest;
    Py_ssize_t count = 0;
    for (Py_ssize_t i = 0; i < n; i++)
        if (s->col[i] > pivot_tol) s->rows[count++] = i;
    if (count > 0) count = keep_smallest(s, count, -1, tol);
    if (count == 0) return -1;
    for (Py_ssize_t k = 0; k < count; k++)
        if (s->basis[s->rows[k]] == artificial) return s->rows[k]; /* z0 leaves: the path ends at a solution */
    /* Break the tie on the rows of B^-1, column by column (never a tie in exact arithmetic). */
    for (Py_ssize_t j = 0; j < n && count > 1; j++) {
        const Py_ssize_t kept = keep_smallest(s, count, j, tol);
        if (kept > 0) count = kept;
    }
    return s->rows[0];
}

/* The first pivot's row: z0 enters (column -d) and the row of the most negative q_i / d_i
 * leaves; ties go to the lexicographically smallest row of [q, I] / d, the largest index. */
static int64_t first_row(const Lemke *s, double tol) {
    double smallest = INFINITY;
    for (Py_ssize_t i = 0; i < s->n; i++)
        if (s->q[i] / s->d[i] < smallest) smallest = s->q[i] / s->d[i];
    int64_t row = 0;
    for (Py_ssize_t i = 0; i < s->n; i++)
        if (s->q[i] / s->d[i] <= smallest + tol * (1.0 + fabs(smallest))) row = i;
    return row;
}

/* Lemke's path from the artificial start; the state's basis and x_B hold the end point. */
static int run(Lemke *s, int64_t max_pivots, double tol, int64_t *pivots) {
    const Py_ssize_t n = s->n;
    const int64_t artificial = 2 * (int64_t)n;
    for (Py_ssize_t i = 0; i < n; i++) {
        for (Py_ssize_t j = 0; j < n; j++) s->Binv[j * n + i] = i == j ? 1.0 : 0.0;
        s->xB[i] = s->q[i];
        s->col[i] = -s->d[i];
    }
    int64_t row = first_row(s, tol);
    int64_t entering = artificial;
    *pivots = 0;
    for (;;) {
        const int64_t leaving = s->basis[row];
        pivot(s, row);
        s->basis[row] = entering;
        *pivots += 1;
        if (leaving == artificial) return SOLUTION;
        if (*pivots >= max_pivots) return PIVOT_LIMIT;
        entering = leaving < n ? leaving + n : leaving - n;
        entering_column(s, entering);
        row = ratio_test(s, artificial, tol);
        if (row < 0) return RAY;
    }
}

/* Lemke's method on raw arrays, no Python objects: the entry point numba kernels call (its address is the
 * module's lemke_address). M (n, n) row-major, q and d (n,); fills z (n,), basis (n,) and *pivots; work
 * (n (n + 3) doubles) and rows (n int64) are scratch space. The caller checks the sizes. Returns the status. */
int64_t quasistatic_lemke(int64_t n, const double *M, const double *q, const double *d, int64_t max_pivots, double tol,
                          double *z, int64_t *basis, int64_t *pivots, double *work, int64_t *rows) {
    Lemke s = {(Py_ssize_t)n, M, q, d, work, work + n * n, work + n * n + n, work + n * n + 2 * n, basis, rows};
    int status = SOLUTION;
    int needs_pivots = 0;
    *pivots = 0;
    for (int64_t i = 0; i < n; i++) {
        basis[i] = i;
        z[i] = 0.0;
        if (!(q[i] >= 0.0)) needs_pivots = 1; /* as np.min(q) >= 0 fails on NaN */
    }
    if (!needs_pivots) return status;
    status = run(&s, max_pivots, tol, pivots);
    for (int64_t i = 0; i < n; i++)
        if (basis[i] >= n && basis[i] < 2 * n) z[basis[i] - n] = s.xB[i];
    return status;
}

/* ---------------------------------------------------------------- buffers and the module */

/* Whether a buffer's format is the one-letter code `code` (native order) with 8-byte items. */
static int has_format(const Py_buffer *view, const char *codes) {
    const char *format = view->format ? view->format : "B";
    if (*format == '@' || *format == '=' || *format == '<') format++;
    return view->itemsize == 8 && format[0] != '\0' && format[1] == '\0' && strchr(codes, format[0]) != NULL;
}

/* Take argument `arg` as a C-contiguous buffer of type `codes` and the given shape (ndim entries). */
static int take_buffer(PyObject *arg, Py_buffer *view, const char *name, const char *codes, int writable, int ndim, const Py_ssize_t *shape) {
    const int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0);
    const char *kind = codes[0] == 'd' ? "float64" : "int64";
    if (PyObject_GetBuffer(arg, view, flags) < 0) {
        if (PyErr_ExceptionMatches(PyExc_BufferError)) { /* not contiguous, or read-only where it is filled */
            PyErr_Clear();
            PyErr_Format(PyExc_ValueError, "%s must be a C-contiguous%s %s array", name, writable ? ", writable" : "", kind);
        }
        return -1;
    }
    int same = view->ndim == ndim;
    for (int k = 0; same && k < ndim; k++) same = view->shape[k] == shape[k];
    if (!has_format(view, codes)) {
        PyErr_Format(PyExc_ValueError, "%s must be a C-contiguous %s array", name, kind);
    } else if (!same) {
        char wanted[96] = "(";
        for (int k = 0; k < ndim; k++)
            snprintf(wanted + strlen(wanted), sizeof wanted - strlen(wanted), k + 1 < ndim ? "%zd, " : ndim == 1 ? "%zd,)" : "%zd)", shape[k]);
        PyErr_Format(PyExc_ValueError, "%s must have shape %s", name, wanted);
    } else {
        return 0;
    }
    PyBuffer_Release(view);
    return -1;
}

static PyObject *lemke(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    (void)module;
    if (nargs != 7) {
        PyErr_SetString(PyExc_TypeError, "lemke(M, q, d, max_pivots, tol, z, basis) takes 7 arguments");
        return NULL;
    }
    const long long max_pivots = PyLong_AsLongLong(args[3]);
    if (max_pivots == -1 && PyErr_Occurred()) return NULL;
    const double tol = PyFloat_AsDouble(args[4]);
    if (tol == -1.0 && PyErr_Occurred()) return NULL;

    Py_buffer views[5];
    int taken = 0;
    PyObject *result = NULL;
    double *memory = NULL;
    Py_ssize_t n;
    {
        Py_buffer probe;
        if (PyObject_GetBuffer(args[1], &probe, PyBUF_STRIDES) < 0) return NULL;
        n = probe.ndim == 1 ? probe.shape[0] : -1;
        PyBuffer_Release(&probe);
        if (n < 0) {
            PyErr_SetString(PyExc_ValueError, "q must be one-dimensional");
            return NULL;
        }
    }
    static const char *names[5] = {"M", "q", "d", "z", "basis"};
    const int inputs[5] = {0, 1, 2, 5, 6};
    for (; taken < 5; taken++) {
        const int writable = taken >= 3;
        const char *codes = taken == 4 ? "ql" : "d";
        const Py_ssize_t shape[2] = {n, n};
        if (take_buffer(args[inputs[taken]], &views[taken], names[taken], codes, writable, taken == 0 ? 2 : 1, shape) < 0) goto done;
    }
    if (n > 0 && (size_t)n > (SIZE_MAX / sizeof(double) - 3) / (size_t)(n + 3)) {
        PyErr_NoMemory();
        goto done;
    }
    /* B^-1, x_B, the column and the ratio values; +1 so that n = 0 asks for a byte */
    memory = PyMem_RawMalloc(((size_t)n * ((size_t)n + 3) + 1) * sizeof(double));
    int64_t *rows = PyMem_RawMalloc(((size_t)n + 1) * sizeof(int64_t));
    if (memory == NULL || rows == NULL) {
        PyMem_RawFree(rows);
        PyErr_NoMemory();
        goto done;
    }
    int64_t status, pivots;
    Py_BEGIN_ALLOW_THREADS
    status = quasistatic_lemke(n, views[0].buf, views[1].buf, views[2].buf, max_pivots, tol, views[3].buf, views[4].buf, &pivots, memory, rows);
    Py_END_ALLOW_THREADS
    PyMem_RawFree(rows);
    result = Py_BuildValue("(LL)", (long long)status, (long long)pivots);
done:
    PyMem_RawFree(memory);
    for (int k = 0; k < taken; k++) PyBuffer_Release(&views[k]);
    return result;
}

/* ---------------------------------------------------------------- the fixed-mode laws */

enum { SEPARATING = 0, ROLLING = 1, SLIDING = 2 };

/* The laws' arrays (row-major): J (m, d, n), b (m, d), mu (m,), g (n,), x (size,), kind and
 * column (m,); out: residual (size,), jacobian (size, size), forces (m, d). */
typedef struct {
    Py_ssize_t m, d, n, size;
    const double *J, *b, *mu, *g, *x;
    const int64_t *kind, *column;
    double *residual, *jacobian, *forces;
} Laws;

/* Friction -mu cn e (e = slip / |slip|) of sliding contact i into the forces, its derivatives into
 * the Jacobian: d/d cn = -mu e, d/d slip = -mu cn (I - e e^T) / |slip|. */
static void sliding_friction(const Laws *L, Py_ssize_t i, double cn, Py_ssize_t col, const double *slip) {
    const Py_ssize_t t = L->d - 1, n = L->n, size = L->size;
    const double *Ji = L->J + i * L->d * n, mu = L->mu[i];
    double sum = 0.0, e[2];
    for (Py_ssize_t s = 0; s < t; s++) sum += slip[s] * slip[s];
    const double speed = sqrt(sum);
    if (speed <= 0.0) return;
    for (Py_ssize_t s = 0; s < t; s++) e[s] = slip[s] / speed;
    const double k = -mu * cn / speed;
    for (Py_ssize_t s = 0; s < t; s++) L->forces[i * L->d + s] = -mu * cn * e[s];
    for (Py_ssize_t j = 0; j < n; j++) {
        for (Py_ssize_t s = 0; s < t; s++) L->jacobian[j * size + col] += Ji[s * n + j] * (-mu * e[s]);
        for (Py_ssize_t k2 = 0; k2 < n; k2++) {
            double total = 0.0;
            for (Py_ssize_t s = 0; s < t; s++)
                for (Py_ssize_t r = 0; r < t; r++) total += Ji[s * n + j] * (k * ((s == r ? 1.0 : 0.0) - e[s] * e[r])) * Ji[r * n + k2];
            L->jacobian[j * size + k2] += total;
        }
    }
}

/* The numba kernel laws/fixed_modes.py::system, loop for loop. */
static void fixed_mode_laws(const Laws *L) {
    const Py_ssize_t m = L->m, d = L->d, n = L->n, size = L->size, t = d - 1;
    for (Py_ssize_t r = 0; r < size; r++) L->residual[r] = 0.0;
    for (Py_ssize_t r = 0; r < size * size; r++) L->jacobian[r] = 0.0;
    for (Py_ssize_t r = 0; r < m * d; r++) L->forces[r] = 0.0;
    for (Py_ssize_t j = 0; j < n; j++) L->residual[j] = L->g[j];
    double slip[2];
    for (Py_ssize_t i = 0; i < m; i++) {
        if (L->kind[i] == SEPARATING) continue;
        const double *Ji = L->J + i * d * n, *bi = L->b + i * d;
        double *fi = L->forces + i * d;
        for (Py_ssize_t s = 0; s < t; s++) {
            slip[s] = -bi[s];
            for (Py_ssize_t j = 0; j < n; j++) slip[s] += Ji[s * n + j] * L->x[j];
        }
        const Py_ssize_t col = (Py_ssize_t)L->column[i];
        const double cn = L->x[col];
        fi[t] = cn;
        /* Closed: no normal velocity; the normal force enters equilibrium. */
        L->residual[col] = -bi[t];
        for (Py_ssize_t j = 0; j < n; j++) {
            L->residual[col] += Ji[t * n + j] * L->x[j];
            L->jacobian[col * size + j] = Ji[t * n + j];
            L->jacobian[j * size + col] += Ji[t * n + j];
        }
        if (L->kind[i] == ROLLING) {
            for (Py_ssize_t s = 0; s < t; s++) {
                const Py_ssize_t row = col + 1 + s;
                fi[s] = L->x[row];
                L->residual[row] = slip[s];
                for (Py_ssize_t j = 0; j < n; j++) {
                    L->jacobian[row * size + j] = Ji[s * n + j];
                    L->jacobian[j * size + row] += Ji[s * n + j];
                }
            }
        } else if (L->mu[i] > 0.0) {
            sliding_friction(L, i, cn, col, slip);
        }
        for (Py_ssize_t j = 0; j < n; j++)
            for (Py_ssize_t s = 0; s < d; s++) L->residual[j] += Ji[s * n + j] * fi[s];
    }
}

/* Whether every closed contact's unknowns lie inside x, after the n twist entries (the kernel
 * trusts `columns`; here a wrong kind or column raises instead of writing out of bounds). */
static int columns_fit(const Laws *L) {
    for (Py_ssize_t i = 0; i < L->m; i++) {
        const int64_t kind = L->kind[i], col = L->column[i];
        if (kind < SEPARATING || kind > SLIDING) {
            PyErr_Format(PyExc_ValueError, "kind[%zd] = %lld is not 0, 1 or 2", i, (long long)kind);
            return 0;
        }
        const int64_t width = kind == ROLLING ? L->d : 1;
        if (kind != SEPARATING && (col < L->n || col > L->size - width)) {
            PyErr_Format(PyExc_ValueError, "column[%zd] = %lld leaves contact %zd's unknowns outside x", i, (long long)col, i);
            return 0;
        }
    }
    return 1;
}

static PyObject *fixed_mode_system(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    (void)module;
    if (nargs != 10) {
        PyErr_SetString(PyExc_TypeError, "fixed_mode_system(J, b, mu, g, x, kind, column, residual, jacobian, forces) takes 10 arguments");
        return NULL;
    }
    Py_buffer probe;
    if (PyObject_GetBuffer(args[0], &probe, PyBUF_STRIDES) < 0) return NULL;
    const int three = probe.ndim == 3;
    const Py_ssize_t m = three ? probe.shape[0] : 0, d = three ? probe.shape[1] : 0, n = three ? probe.shape[2] : 0;
    PyBuffer_Release(&probe);
    if (!three || d < 2 || d > 3) {
        PyErr_SetString(PyExc_ValueError, "J must have shape (m, d, n) with d = 2 or 3");
        return NULL;
    }
    if (PyObject_GetBuffer(args[4], &probe, PyBUF_STRIDES) < 0) return NULL;
    const Py_ssize_t size = probe.ndim == 1 ? probe.shape[0] : -1;
    PyBuffer_Release(&probe);
    if (size < n) {
        PyErr_SetString(PyExc_ValueError, "x must be one-dimensional, the twist's n entries first");
        return NULL;
    }
    static const char *names[10] = {"J", "b", "mu", "g", "x", "kind", "column", "residual", "jacobian", "forces"};
    const int ndims[10] = {3, 2, 1, 1, 1, 1, 1, 1, 2, 2};
    const Py_ssize_t shapes[10][3] = {{m, d, n}, {m, d}, {m}, {n}, {size}, {m}, {m}, {size}, {size, size}, {m, d}};
    Py_buffer views[10];
    int taken = 0;
    PyObject *result = NULL;
    for (; taken < 10; taken++) {
        const char *codes = taken == 5 || taken == 6 ? "ql" : "d";
        if (take_buffer(args[taken], &views[taken], names[taken], codes, taken >= 7, ndims[taken], shapes[taken]) < 0) goto done;
    }
    const Laws L = {m, d, n, size, views[0].buf, views[1].buf, views[2].buf, views[3].buf, views[4].buf,
                    views[5].buf, views[6].buf, views[7].buf, views[8].buf, views[9].buf};
    if (!columns_fit(&L)) goto done;
    Py_BEGIN_ALLOW_THREADS
    fixed_mode_laws(&L);
    Py_END_ALLOW_THREADS
    result = Py_NewRef(Py_None);
done:
    for (int k = 0; k < taken; k++) PyBuffer_Release(&views[k]);
    return result;
}

static PyMethodDef methods[] = {
    {"lemke", (PyCFunction)(void (*)(void))lemke, METH_FASTCALL,
     "lemke(M, q, d, max_pivots, tol, z, basis) -> (status, pivots): Lemke's method, the numba kernel's rules;\n"
     "fills z (n,) float64 and basis (n,) int64. See quasistatic.solvers.numerics.lemke."},
    {"fixed_mode_system", (PyCFunction)(void (*)(void))fixed_mode_system, METH_FASTCALL,
     "fixed_mode_system(J, b, mu, g, x, kind, column, residual, jacobian, forces): the fixed-mode laws at x,\n"
     "the numba kernel's loops; fills residual (N,), jacobian (N, N) and forces (m, d). See quasistatic.laws.fixed_modes."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module_definition = {
    PyModuleDef_HEAD_INIT, "quasistatic._lemke", "Lemke's method and the fixed-mode laws compiled (no numpy headers): see quasistatic.compiled.", -1, methods, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__lemke(void) {
    PyObject *module = PyModule_Create(&module_definition);
    if (module == NULL) return NULL;
    PyObject *address = PyLong_FromVoidPtr((void *)quasistatic_lemke);
    if (address == NULL || PyModule_AddObject(module, "lemke_address", address) < 0) {
        Py_XDECREF(address);
        Py_DECREF(module);
        return NULL;
    }
    return module;
}
