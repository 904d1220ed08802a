/* Compiled kernels, each making the numba kernel's choices:
 *
 *   lemke(M, q, d, max_pivots, tol, free, z, basis) -> (status, pivots)
 *       Lemke's method with lexicographic anti-cycling, solvers/numerics/lemke.py's numba kernel
 *       pivot for pivot. M: (n, n) float64, q and d: (n,) float64; z: (n,) float64 and basis: (n,)
 *       int64 are filled; z_0 .. z_{free-1} are free (they never leave the basis once they enter). NaN
 *       never qualifies in a comparison, so NaN data end on a ray or at max_pivots, never in a loop or
 *       out of bounds.
 *   solve_split_lcp(J, b, mu, g, frictional, base, exact, free_twist, gap_covering, ..., q, c) -> (status, stage, pivots, realignments)
 *       The fast path's whole kernel, solvers/numerics/lcp.py::solve_split_lcp step for step.
 *   lemke_address
 *       The address of quasistatic_lemke, the same method on raw pointers (no Python objects):
 *       the numba install's kernels call it from compiled code.
 *   exact_newton(J, b, mu, g, q, c, depth, patience, one_switch, mode_tol, tol, cone_roundoff, newton_damping, newton_stop,
 *                q_out, c_out) -> bool
 *       Newton's method on the exact 3-D fixed-mode laws from (q, c), solvers/numerics/lcp.py::_newton step
 *       for step (the kernel's own Newton, called alone); q_out (n,) and c_out (m, 3) are filled.
 *   api_version
 *       7; quasistatic/compiled.py runs without a .so built from an older source.
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

/* Lemke's two N x N loops (a pivot's update of B^-1, the entering column) compiled twice where the toolchain can (GCC
 * or clang with glibc's ifunc on x86-64): with AVX2, four doubles an instruction, and for any x86-64; the loader picks
 * the one the machine runs. AVX2 brings no fused multiply-add (that is FMA, not asked for), so every product and sum
 * is rounded as in the plain build: the same bits, 1.3-1.5x faster kernels on grasp-3d (docs/performance.md). */
#if defined(__x86_64__) && defined(__GLIBC__) && defined(__has_attribute)
#if __has_attribute(target_clones)
#define WIDE_LOOPS __attribute__((target_clones("avx2", "default")))
#endif
#endif
#ifndef WIDE_LOOPS
#define WIDE_LOOPS
#endif

/* One run's state: B^-1 column-major (each step below is a loop down contiguous columns,
 * which the compiler vectorizes), the basic values, the entering column, the basis, and
 * the candidate rows of the ratio test with their values. */
typedef struct {
    Py_ssize_t n;
    int64_t n_free; /* z_0 .. z_{free-1} never leave the basis (a mixed LCP's free variables) */
    const double *M, *q, *d;
    double *Binv, *xB, *col, *values;
    int64_t *basis, *rows;
} Lemke;

/* Eliminate the entering column on `row`, in the kernel's arithmetic: the pivot row times the
 * reciprocal of the pivot, then every row minus its factor (the column, 0 on `row`) times it. */
WIDE_LOOPS static void pivot(Lemke *s, int64_t row) {
    const Py_ssize_t n = s->n;
    const double scale = 1.0 / s->col[row];
    double *restrict factors = s->col; /* the column is not needed after this pivot */
    factors[row] = 0.0;
    for (Py_ssize_t j = 0; j < n; j++) {
        double *restrict column = s->Binv + j * n;
        const double value = column[row] * scale;
        if (value != 0.0) /* B^-1 fills in over the pivots: x - 0 y is x for finite y */
            for (Py_ssize_t i = 0; i < n; i++) column[i] -= factors[i] * value;
        column[row] = value;
    }
    const double value = s->xB[row] * scale;
    for (Py_ssize_t i = 0; i < n; i++) s->xB[i] -= factors[i] * value;
    s->xB[row] = value;
}

/* B^-1 A_e for the entering variable's column A_e of [I, -M, -d]: each entry summed over j in
 * order, as a dot product of a row of B^-1 would be, then negated for -M and -d. */
WIDE_LOOPS static void entering_column(Lemke *s, int64_t entering) {
    const Py_ssize_t n = s->n;
    double *restrict col = s->col;
    if (entering < n) {
        for (Py_ssize_t i = 0; i < n; i++) col[i] = s->Binv[entering * n + i];
        return;
    }
    for (Py_ssize_t i = 0; i < n; i++) col[i] = 0.0;
    for (Py_ssize_t j = 0; j < n; j++) {
        const double a = entering < 2 * n ? s->M[j * n + (entering - n)] : s->d[j];
        if (a == 0.0) continue; /* the split LCP's columns are mostly zeros; x + 0 y is x for finite y */
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
 * column is above the pivot tolerance (relative to its largest magnitude) in a row whose
 * basic variable may leave (every row but a free variable's: a free variable has no bound). */
static int64_t ratio_test(Lemke *s, int64_t artificial, double tol) {
    const Py_ssize_t n = s->n;
    double largest = 1.0;
    for (Py_ssize_t i = 0; i < n; i++)
        if (fabs(s->col[i]) > largest) largest = fabs(s->col[i]);
    const double pivot_tol = tol * largest;
    Py_ssize_t count = 0;
    for (Py_ssize_t i = 0; i < n; i++)
        if (s->col[i] > pivot_tol && !(s->basis[i] >= n && s->basis[i] < n + s->n_free)) s->rows[count++] = i;
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
 * module's lemke_address). M (n, n) row-major, q and d (n,); z_0 .. z_{free-1} are free (never leave the basis once
 * they enter, so their values may turn negative); fills z (n,), basis (n,) and *pivots; work (n (n + 3) doubles) and
 * rows (n int64) are scratch space. The caller checks the sizes. Returns the status. */
int64_t quasistatic_lemke(int64_t n, const double *M, const double *q, const double *d, int64_t max_pivots, double tol, int64_t n_free,
                          double *z, int64_t *basis, int64_t *pivots, double *work, int64_t *rows) {
    Lemke s = {(Py_ssize_t)n, n_free, M, q, d, work, work + n * n, work + n * n + n, work + n * n + 2 * n, basis, rows};
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
    if (nargs != 8) {
        PyErr_SetString(PyExc_TypeError, "lemke(M, q, d, max_pivots, tol, free, z, basis) takes 8 arguments");
        return NULL;
    }
    const long long max_pivots = PyLong_AsLongLong(args[3]);
    if (max_pivots == -1 && PyErr_Occurred()) return NULL;
    const double tol = PyFloat_AsDouble(args[4]);
    if (tol == -1.0 && PyErr_Occurred()) return NULL;
    const long long n_free = PyLong_AsLongLong(args[5]);
    if (n_free == -1 && PyErr_Occurred()) return NULL;

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
    const int inputs[5] = {0, 1, 2, 6, 7};
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
    status = quasistatic_lemke(n, views[0].buf, views[1].buf, views[2].buf, max_pivots, tol, n_free, views[3].buf, views[4].buf, &pivots, memory,
                               rows);
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
 * column (m,); out: residual (size,), jacobian (size, size), forces (m, d). A NULL jacobian: the residual
 * and forces alone (the same bits), for the line search's trial points, most of which are rejected. */
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
    if (L->jacobian == NULL) return;
    /* The kernel's factors of each term, computed once rather than in its innermost loop: the same values, the same sums. */
    double pull[2], bend[2][2];
    for (Py_ssize_t s = 0; s < t; s++) {
        pull[s] = -mu * e[s];
        for (Py_ssize_t r = 0; r < t; r++) bend[s][r] = k * ((s == r ? 1.0 : 0.0) - e[s] * e[r]);
    }
    for (Py_ssize_t j = 0; j < n; j++) {
        double left[2][2]; /* each term's first product, Ji[s, j] bend[s][r] */
        for (Py_ssize_t s = 0; s < t; s++) {
            L->jacobian[j * size + col] += Ji[s * n + j] * pull[s];
            for (Py_ssize_t r = 0; r < t; r++) left[s][r] = Ji[s * n + j] * bend[s][r];
        }
        for (Py_ssize_t k2 = 0; k2 < n; k2++) {
            double total = 0.0;
            for (Py_ssize_t s = 0; s < t; s++)
                for (Py_ssize_t r = 0; r < t; r++) total += left[s][r] * Ji[r * n + k2];
            L->jacobian[j * size + k2] += total;
        }
    }
}

/* The numba kernel laws/fixed_modes.py::system, its arithmetic in its order (a contact's d velocity sums run side by
 * side, each in the kernel's order). With L->jacobian NULL, the residual and forces only. */
static void fixed_mode_laws(const Laws *L) {
    const Py_ssize_t m = L->m, d = L->d, n = L->n, size = L->size, t = d - 1;
    for (Py_ssize_t r = 0; r < size; r++) L->residual[r] = 0.0;
    double *jacobian = L->jacobian;
    if (jacobian != NULL)
        for (Py_ssize_t r = 0; r < size * size; r++) jacobian[r] = 0.0;
    for (Py_ssize_t r = 0; r < m * d; r++) L->forces[r] = 0.0;
    for (Py_ssize_t j = 0; j < n; j++) L->residual[j] = L->g[j];
    double u[3]; /* the contact's velocity: its slip (t entries), then its normal velocity */
    for (Py_ssize_t i = 0; i < m; i++) {
        if (L->kind[i] == SEPARATING) continue;
        const double *Ji = L->J + i * d * n, *bi = L->b + i * d;
        double *fi = L->forces + i * d;
        for (Py_ssize_t s = 0; s < d; s++) u[s] = -bi[s];
        for (Py_ssize_t j = 0; j < n; j++)
            for (Py_ssize_t s = 0; s < d; s++) u[s] += Ji[s * n + j] * L->x[j];
        const Py_ssize_t col = (Py_ssize_t)L->column[i];
        const double cn = L->x[col];
        fi[t] = cn;
        /* Closed: no normal velocity; the normal force enters equilibrium. */
        L->residual[col] = u[t];
        if (jacobian != NULL)
            for (Py_ssize_t j = 0; j < n; j++) {
                jacobian[col * size + j] = Ji[t * n + j];
                jacobian[j * size + col] += Ji[t * n + j];
            }
        if (L->kind[i] == ROLLING) {
            for (Py_ssize_t s = 0; s < t; s++) {
                const Py_ssize_t row = col + 1 + s;
                fi[s] = L->x[row];
                L->residual[row] = u[s];
                if (jacobian != NULL)
                    for (Py_ssize_t j = 0; j < n; j++) {
                        jacobian[row * size + j] = Ji[s * n + j];
                        jacobian[j * size + row] += Ji[s * n + j];
                    }
            }
        } else if (L->mu[i] > 0.0) {
            sliding_friction(L, i, cn, col, u);
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

/* ---------------------------------------------------------------- the split-twist LCP kernel */

enum { NOT_CONVERGED = 3 };
enum { NEWTON_ITERATIONS = 50 }; /* most Newton iterations a set of contact modes gets (lcp.py::NEWTON_ITERATIONS) */

/* Python's max(a, b) as numba compiles it: b only when b > a, so a NaN in b is passed over and one in a kept. */
static double py_max(double a, double b) { return b > a ? b : a; }

/* The largest magnitude, NaN when any entry is NaN (as np.max(np.abs(r))). */
static double largest_magnitude(Py_ssize_t count, const double *r) {
    double largest = 0.0;
    for (Py_ssize_t i = 0; i < count; i++) {
        if (isnan(r[i])) return NAN;
        if (fabs(r[i]) > largest) largest = fabs(r[i]);
    }
    return largest;
}

/* A x = rhs by Gaussian elimination with partial pivoting, lcp.py::_linear_solve step for step: A (k, k) row-major is
 * copied into U; x holds the solution, or where a pivot is within 1e-14 of A's largest entry (the kernel's threshold)
 * the partly eliminated right-hand side, and 0 is returned (singular). */
static int linear_solve(Py_ssize_t k, const double *A, const double *rhs, double *U, double *x) {
    double scale = 0.0;
    for (Py_ssize_t i = 0; i < k * k; i++) {
        U[i] = A[i];
        scale = py_max(scale, fabs(A[i]));
    }
    for (Py_ssize_t i = 0; i < k; i++) x[i] = rhs[i];
    const double tiny = 1e-14 * py_max(scale, 1e-300);
    for (Py_ssize_t c = 0; c < k; c++) {
        Py_ssize_t p = c;
        for (Py_ssize_t i = c + 1; i < k; i++)
            if (fabs(U[i * k + c]) > fabs(U[p * k + c])) p = i;
        if (fabs(U[p * k + c]) <= tiny) return 0;
        if (p != c) {
            for (Py_ssize_t j = 0; j < k; j++) {
                const double swap = U[c * k + j];
                U[c * k + j] = U[p * k + j];
                U[p * k + j] = swap;
            }
            const double swap = x[c];
            x[c] = x[p];
            x[p] = swap;
        }
        for (Py_ssize_t i = c + 1; i < k; i++) {
            const double factor = U[i * k + c] / U[c * k + c];
            if (factor != 0.0) {
                for (Py_ssize_t j = c; j < k; j++) U[i * k + j] -= factor * U[c * k + j];
                x[i] -= factor * x[c];
            }
        }
    }
    for (Py_ssize_t c = k - 1; c >= 0; c--) {
        double total = x[c];
        for (Py_ssize_t j = c + 1; j < k; j++) total -= U[c * k + j] * x[j];
        x[c] = total / U[c * k + c];
    }
    return 1;
}

/* One problem's data and tolerances, and the scratch space of every step (sizes in split_lcp's allocation). */
typedef struct {
    Py_ssize_t m, d, n, f, K, N; /* contacts, contact dimension, twist size, frictional contacts, edges, LCP size */
    const double *J, *b, *mu, *g, *base;
    const int64_t *frictional;
    double mode_tol, dissipation_tol, pivot_tol, feasibility_tol, cone_roundoff, newton_damping, newton_stop;
    int64_t pivots_per_row;
    int free_twist;      /* the twist halves q+, q- free in Lemke's method (kept basic once they enter) */
    double gap_covering; /* the covering vector's entries on the gap rates' rows (1 elsewhere) */
    /* the LCP */
    double *Jn, *bn, *Jt, *bt, *mu_f, *offsets, *edges, *M, *qv, *covering, *z, *work, *A, *rhs, *U, *solution;
    int64_t *basis, *rows, *basic;
    /* Newton's method (sizes up to n + 3 m unknowns) */
    double *x, *trial, *residual, *jacobian, *r_trial, *j_trial, *forces, *f_trial, *normal, *gradient, *step, *newton_q;
    int64_t *kind, *column;
} Split;

/* Normal rows of every contact; tangent rows and mu of the frictional ones (lcp.py::_split_rows). */
static void split_rows(Split *s) {
    const Py_ssize_t d = s->d, n = s->n, t = d - 1;
    for (Py_ssize_t i = 0; i < s->m; i++) {
        s->bn[i] = s->b[i * d + t];
        for (Py_ssize_t j = 0; j < n; j++) s->Jn[i * n + j] = s->J[(i * d + t) * n + j];
    }
    for (Py_ssize_t a = 0; a < s->f; a++) {
        const int64_t i = s->frictional[a];
        s->mu_f[a] = s->mu[i];
        for (Py_ssize_t r = 0; r < t; r++) {
            s->bt[a * t + r] = s->b[i * d + r];
            for (Py_ssize_t j = 0; j < n; j++) s->Jt[(a * t + r) * n + j] = s->J[(i * d + r) * n + j];
        }
    }
}

/* Edge directions (f, K, t): the 2-D signs, or 3-D angles base + offset per contact (lcp.py::_edges). */
static void edges(Split *s) {
    const Py_ssize_t K = s->K, t = s->d - 1;
    for (Py_ssize_t a = 0; a < s->f; a++)
        for (Py_ssize_t k = 0; k < K; k++) {
            double *e = s->edges + (a * K + k) * t;
            if (t == 1) {
                e[0] = s->base[k];
            } else {
                e[0] = cos(s->base[k] + s->offsets[a]);
                e[1] = sin(s->base[k] + s->offsets[a]);
            }
        }
}

/* The LCP matrix M (N, N) and vector qv (N,) of the split-twist polyhedral laws (lcp.py::_assemble, loop for loop). */
static void assemble(Split *s) {
    const Py_ssize_t m = s->m, n = s->n, f = s->f, K = s->K, N = s->N, t = s->d - 1;
    const Py_ssize_t cn0 = 2 * n, b0 = cn0 + m, l0 = b0 + f * K;
    double *M = s->M, *q = s->qv;
    for (Py_ssize_t i = 0; i < N * N; i++) M[i] = 0.0;
    for (Py_ssize_t i = 0; i < N; i++) q[i] = 0.0;
    for (Py_ssize_t i = 0; i < n; i++) {
        q[i] = -s->g[i];
        q[n + i] = s->g[i];
    }
    for (Py_ssize_t j = 0; j < m; j++) {
        q[cn0 + j] = -s->bn[j];
        for (Py_ssize_t i = 0; i < n; i++) {
            const double a = s->Jn[j * n + i];
            M[(cn0 + j) * N + i] = a;
            M[(cn0 + j) * N + n + i] = -a;
            M[i * N + cn0 + j] = -a;
            M[(n + i) * N + cn0 + j] = a;
        }
    }
    for (Py_ssize_t a = 0; a < f; a++) {
        const Py_ssize_t row_l = l0 + a;
        M[row_l * N + cn0 + s->frictional[a]] = s->mu_f[a];
        for (Py_ssize_t k = 0; k < K; k++) {
            const Py_ssize_t row = b0 + a * K + k;
            const double *e = s->edges + (a * K + k) * t;
            double rhs = 0.0;
            for (Py_ssize_t r = 0; r < t; r++) rhs += e[r] * s->bt[a * t + r];
            q[row] = -rhs;
            for (Py_ssize_t i = 0; i < n; i++) {
                double value = 0.0;
                for (Py_ssize_t r = 0; r < t; r++) value += e[r] * s->Jt[(a * t + r) * n + i];
                M[row * N + i] = value;
                M[row * N + n + i] = -value;
                M[i * N + row] = -value;
                M[(n + i) * N + row] = value;
            }
            M[row * N + row_l] = 1.0;
            M[row_l * N + row] = -1.0;
        }
    }
}

/* Lemke's method on the assembled LCP from the artificial start; fills z and basis, adds its pivots. */
static int64_t split_lemke(Split *s, int64_t *pivots) {
    int64_t more = 0;
    const int64_t n_free = s->free_twist ? 2 * s->n : 0;
    const int64_t status = quasistatic_lemke(s->N, s->M, s->qv, s->covering, s->pivots_per_row * s->N, s->pivot_tol, n_free, s->z, s->basis,
                                             &more, s->work, s->rows);
    *pivots += more;
    return status;
}

/* Twist q (n,) and contact-frame forces c (m, d) of z = [q+, q-, cn, beta, lam] (lcp.py::_motion). */
static void motion(const Split *s, double *q, double *c) {
    const Py_ssize_t m = s->m, d = s->d, n = s->n, K = s->K, t = d - 1;
    for (Py_ssize_t j = 0; j < n; j++) q[j] = s->z[j] - s->z[n + j];
    for (Py_ssize_t i = 0; i < m * d; i++) c[i] = 0.0;
    for (Py_ssize_t i = 0; i < m; i++) c[i * d + t] = s->z[2 * n + i];
    const Py_ssize_t start = 2 * n + m;
    for (Py_ssize_t a = 0; a < s->f; a++)
        for (Py_ssize_t k = 0; k < K; k++) {
            const double beta = s->z[start + a * K + k];
            for (Py_ssize_t r = 0; r < t; r++) c[s->frictional[a] * d + r] += beta * s->edges[(a * K + k) * t + r];
        }
}

/* The LCP solution with the last complementary basis (M_SS z_S = -q_S) into z, and whether it is feasible
 * (lcp.py::_basis_solution; free twist halves may be negative). */
static int basis_solution(Split *s) {
    const Py_ssize_t N = s->N;
    Py_ssize_t count = 0;
    for (Py_ssize_t i = 0; i < N; i++)
        if (s->basis[i] >= N && s->basis[i] < 2 * N) s->basic[count++] = s->basis[i] - N;
    for (Py_ssize_t i = 0; i < N; i++) s->z[i] = 0.0;
    if (count) {
        for (Py_ssize_t r = 0; r < count; r++) {
            s->rhs[r] = -s->qv[s->basic[r]];
            for (Py_ssize_t c = 0; c < count; c++) s->A[r * count + c] = s->M[s->basic[r] * N + s->basic[c]];
        }
        if (!linear_solve(count, s->A, s->rhs, s->U, s->solution)) return 0; /* the basis does not carry over */
        const int64_t n_free = s->free_twist ? 2 * s->n : 0;
        for (Py_ssize_t r = 0; r < count; r++) {
            if (s->basic[r] < n_free) {
                s->z[s->basic[r]] = s->solution[r];
                continue;
            }
            if (s->solution[r] < -s->feasibility_tol) return 0;
            s->z[s->basic[r]] = py_max(s->solution[r], 0.0);
        }
    }
    for (Py_ssize_t i = 0; i < N; i++) {
        double w = s->qv[i];
        for (Py_ssize_t j = 0; j < N; j++) w += s->M[i * N + j] * s->z[j];
        if (w < -s->feasibility_tol) return 0;
    }
    return 1;
}

/* Normal velocity and slip speed of 3-D contact i at twist q (lcp.py::_contact_speeds). */
static void contact_speeds(const Split *s, const double *q, Py_ssize_t i, double *normal, double *speed) {
    const Py_ssize_t n = s->n;
    double u[3];
    for (Py_ssize_t r = 0; r < 3; r++) {
        u[r] = -s->b[i * 3 + r];
        for (Py_ssize_t j = 0; j < n; j++) u[r] += s->J[(i * 3 + r) * n + j] * q[j];
    }
    *normal = u[2];
    *speed = sqrt(u[0] * u[0] + u[1] * u[1]);
}

/* The fixed-mode laws at x into out (residual, Jacobian, forces), with the kind and columns of s. */
static void laws_at(const Split *s, Py_ssize_t size, const double *x, double *residual, double *jacobian, double *forces) {
    const Laws L = {s->m, 3, s->n, size, s->J, s->b, s->mu, s->g, x, s->kind, s->column, residual, jacobian, forces};
    fixed_mode_laws(&L);
}

/* Newton step -(J^T J + lam I)^-1 J^T r into s->step (lcp.py::_newton_step, loop for loop). */
static void newton_step(Split *s, Py_ssize_t size) {
    const double *jac = s->jacobian, *res = s->residual;
    double *normal = s->normal, *gradient = s->gradient;
    for (Py_ssize_t i = 0; i < size * size; i++) normal[i] = 0.0;
    double largest = 0.0;
    for (Py_ssize_t i = 0; i < size; i++) {
        gradient[i] = 0.0;
        for (Py_ssize_t k = 0; k < size; k++) {
            const double a = jac[k * size + i];
            if (a == 0.0) continue; /* a force column is zero in the contacts' rows: x - 0 y is x for finite y, +0 + -0 is +0 */
            gradient[i] -= a * res[k];
            for (Py_ssize_t j = i; j < size; j++) normal[i * size + j] += a * jac[k * size + j];
        }
        /* J^T J is symmetric: row i left of the diagonal is column i above it, summed over k in the same order of
         * the same products (a b = b a exactly), so copied, not summed again. */
        for (Py_ssize_t j = 0; j < i; j++) normal[i * size + j] = normal[j * size + i];
        largest = py_max(largest, normal[i * size + i]);
    }
    for (Py_ssize_t i = 0; i < size; i++) normal[i * size + i] += s->newton_damping * (1.0 + largest);
    linear_solve(size, normal, gradient, s->U, s->step); /* singular or not, the kernel takes what comes out */
}

/* Whether lcp.py::_newton would switch a contact's mode at the twist q and forces (m, 3) (lcp.py::_switch_due). */
static int switch_due(const Split *s, const double *q, const double *forces) {
    double u_n, speed;
    for (Py_ssize_t i = 0; i < s->m; i++) {
        contact_speeds(s, q, i, &u_n, &speed);
        if ((s->kind[i] == SEPARATING && u_n < 0.0) || (s->kind[i] != SEPARATING && forces[i * 3 + 2] < 0.0)) return 1;
        if (s->kind[i] == SLIDING && s->mu[i] > 0.0 && speed <= s->mode_tol) return 1;
    }
    return 0;
}

/* Damped Newton steps with step halving on the fixed-mode laws from s->x (lcp.py::_gauss_newton): at most NEWTON_ITERATIONS,
 * or until patience of them have not halved the residual while a mode switch is due. s->x, s->residual, s->jacobian and
 * s->forces end at the last accepted point; returns its largest residual. */
static double gauss_newton(Split *s, Py_ssize_t size, long long patience) {
    laws_at(s, size, s->x, s->residual, s->jacobian, s->forces);
    double norm = largest_magnitude(size, s->residual);
    double reference = norm;
    long long stalled = 0;
    for (int iteration = 0; iteration < NEWTON_ITERATIONS; iteration++) {
        if (norm <= s->newton_stop) break;
        newton_step(s, size);
        double t = 1.0;
        int improved = 0;
        for (int halving = 0; halving < 30; halving++) {
            for (Py_ssize_t i = 0; i < size; i++) s->trial[i] = s->x[i] + t * s->step[i];
            laws_at(s, size, s->trial, s->r_trial, NULL, s->f_trial); /* most trials fail: their Jacobian is not needed */
            const double n_trial = largest_magnitude(size, s->r_trial);
            if (n_trial < norm) {
                laws_at(s, size, s->trial, s->r_trial, s->j_trial, s->f_trial); /* the same residual, with the Jacobian */
                double *swap;
                swap = s->x, s->x = s->trial, s->trial = swap;
                swap = s->residual, s->residual = s->r_trial, s->r_trial = swap;
                swap = s->jacobian, s->jacobian = s->j_trial, s->j_trial = swap;
                swap = s->forces, s->forces = s->f_trial, s->f_trial = swap;
                norm = n_trial;
                improved = 1;
                break;
            }
            t *= 0.5;
        }
        if (!improved) break;
        if (norm <= 0.5 * reference) {
            reference = norm, stalled = 0;
            continue;
        }
        stalled++;
        if (stalled >= patience && switch_due(s, s->x, s->forces)) break;
    }
    return norm;
}

/* The exact 3-D laws with the contact modes of (q, c), by lcp.py::_newton's rules (a contact closed where its gap rate
 * is at most depth below mode_tol; with one_switch, a round switches only the first contact that must switch); the result
 * in s->newton_q and s->forces (m, 3). Returns whether it converged with every mode and inequality kept. */
static int newton(Split *s, const double *q, const double *c, double depth, long long patience, int one_switch, double tol) {
    const Py_ssize_t m = s->m, n = s->n;
    double u_n, speed;
    for (Py_ssize_t i = 0; i < m; i++) {
        contact_speeds(s, q, i, &u_n, &speed);
        s->kind[i] = u_n + depth <= s->mode_tol ? (s->mu[i] > 0.0 && speed <= s->mode_tol ? ROLLING : SLIDING) : SEPARATING;
    }
    for (Py_ssize_t i = 0; i < m * 3; i++) s->forces[i] = c[i];
    for (Py_ssize_t j = 0; j < n; j++) s->newton_q[j] = q[j];
    for (int round = 0; round < 8; round++) {
        Py_ssize_t size = n;
        for (Py_ssize_t i = 0; i < m; i++) {
            s->column[i] = size;
            size += s->kind[i] == SEPARATING ? 0 : (s->kind[i] == ROLLING ? 3 : 1);
        }
        for (Py_ssize_t r = 0; r < size; r++) s->x[r] = 0.0;
        for (Py_ssize_t j = 0; j < n; j++) s->x[j] = s->newton_q[j];
        for (Py_ssize_t i = 0; i < m; i++) {
            const double *fi = s->forces + i * 3;
            if (s->kind[i] != SEPARATING) s->x[s->column[i]] = py_max(fi[2], 0.0);
            if (s->kind[i] == ROLLING) {
                s->x[s->column[i] + 1] = fi[0];
                s->x[s->column[i] + 2] = fi[1];
            }
        }
        const double norm = gauss_newton(s, size, patience);
        for (Py_ssize_t j = 0; j < n; j++) s->newton_q[j] = s->x[j];
        int changed = 0;
        for (Py_ssize_t i = 0; i < m && !(changed && one_switch); i++) {
            double *fi = s->forces + i * 3;
            contact_speeds(s, s->newton_q, i, &u_n, &speed);
            if (s->kind[i] == SEPARATING && u_n < 0.0) {
                s->kind[i] = s->mu[i] > 0.0 && speed <= s->mode_tol ? ROLLING : SLIDING;
                changed = 1;
            } else if (s->kind[i] != SEPARATING && fi[2] < 0.0) {
                s->kind[i] = SEPARATING;
                fi[0] = fi[1] = fi[2] = 0.0;
                changed = 1;
            } else if (s->kind[i] == SLIDING && s->mu[i] > 0.0 && speed <= s->mode_tol) {
                s->kind[i] = ROLLING;
                changed = 1;
            }
        }
        if (changed) continue;
        int ok = norm <= tol;
        for (Py_ssize_t i = 0; i < m; i++) {
            const double *fi = s->forces + i * 3;
            if (s->kind[i] == ROLLING) ok = ok && sqrt(fi[0] * fi[0] + fi[1] * fi[1]) <= s->mu[i] * fi[2] * (1.0 + s->cone_roundoff);
        }
        return ok;
    }
    return 0;
}

/* The largest distance of a sliding contact's friction from -mu cn slip/|slip| at (q, c), each such contact's edge offset
 * turned opposite its slip (the loop at the top of lcp.py::solve_split_lcp's re-alignment). */
static double misalignment(Split *s, const double *q, const double *c) {
    const Py_ssize_t n = s->n;
    double error = 0.0;
    for (Py_ssize_t a = 0; a < s->f; a++) {
        const int64_t i = s->frictional[a];
        double slip[2];
        for (Py_ssize_t r = 0; r < 2; r++) {
            slip[r] = -s->bt[a * 2 + r];
            for (Py_ssize_t j = 0; j < n; j++) slip[r] += s->Jt[(a * 2 + r) * n + j] * q[j];
        }
        const double speed = sqrt(slip[0] * slip[0] + slip[1] * slip[1]);
        if (speed > s->mode_tol) {
            const double scale = s->mu_f[a] * c[i * 3 + 2] / speed;
            const double x = c[i * 3] + scale * slip[0], y = c[i * 3 + 1] + scale * slip[1];
            error = py_max(error, sqrt(x * x + y * y));
            s->offsets[a] = atan2(-slip[1], -slip[0]);
        }
    }
    return error;
}

typedef struct {
    int64_t status, stage, pivots, realignments;
} SplitResult;

/* lcp.py::solve_split_lcp: Lemke on the split-twist LCP, then (exact 3-D cones) edge re-alignment and Newton's method;
 * the twist into q (n,) and the contact-frame forces into c (m, d). */
static SplitResult split_lcp(Split *s, int exact, int64_t max_realignments, double *q, double *c) {
    SplitResult out = {0, 0, 0, 0};
    split_rows(s);
    for (Py_ssize_t a = 0; a < s->f; a++) s->offsets[a] = 0.0;
    edges(s);
    assemble(s);
    out.status = split_lemke(s, &out.pivots);
    motion(s, q, c);
    if (out.status != SOLUTION || !exact) return out;
    double previous = INFINITY;
    for (;;) {
        const double error = misalignment(s, q, c);
        if (error <= s->dissipation_tol) {
            out.stage = out.realignments < 1 ? out.realignments : 1;
            return out;
        }
        if (out.realignments == 0 || out.realignments == max_realignments || error > 0.5 * previous) {
            /* First, and whenever re-alignment stalls: the exact laws with these contact modes. */
            if (newton(s, q, c, 0.0, NEWTON_ITERATIONS, 0, s->dissipation_tol)) {
                for (Py_ssize_t j = 0; j < s->n; j++) q[j] = s->newton_q[j];
                for (Py_ssize_t i = 0; i < s->m * 3; i++) c[i] = s->forces[i];
                out.stage = 2;
                return out;
            }
            if (out.realignments == max_realignments) {
                out.status = NOT_CONVERGED;
                out.stage = 2;
                return out;
            }
        }
        previous = error;
        out.realignments += 1;
        edges(s);
        assemble(s);
        if (!basis_solution(s)) {
            out.status = split_lemke(s, &out.pivots);
            if (out.status != SOLUTION) {
                motion(s, q, c);
                out.stage = 1;
                return out;
            }
        }
        motion(s, q, c);
    }
}

enum { LARGEST_SPLIT = 1 << 20 }; /* LCP rows and Newton unknowns at most: keeps every size below in size_t */

/* Lay the scratch arrays of s out in `memory` (doubles) and `integers` (int64, 3 N + 2 m of them) and set the covering
 * vector (gap_covering on the gap rates' rows, 1 elsewhere); with memory NULL, only count. Returns the doubles used. */
static size_t lay_out(Split *s, double *memory, int64_t *integers) {
    const Py_ssize_t m = s->m, n = s->n, f = s->f, K = s->K, t = s->d - 1, N = s->N, S = n + 3 * m;
    size_t used = 0;
#define TAKE(field, count) (s->field = memory ? memory + used : NULL, used += (size_t)(count))
    TAKE(Jn, m * n), TAKE(bn, m), TAKE(Jt, f * t * n), TAKE(bt, f * t), TAKE(mu_f, f), TAKE(offsets, f), TAKE(edges, f * K * t);
    TAKE(M, N * N), TAKE(qv, N), TAKE(covering, N), TAKE(z, N), TAKE(work, N * (N + 3)), TAKE(A, N * N), TAKE(rhs, N);
    TAKE(U, N > S ? N * N : S * S), TAKE(solution, N);
    TAKE(x, S), TAKE(trial, S), TAKE(residual, S), TAKE(jacobian, S * S), TAKE(r_trial, S), TAKE(j_trial, S * S);
    TAKE(forces, 3 * m), TAKE(f_trial, 3 * m), TAKE(normal, S * S), TAKE(gradient, S), TAKE(step, S), TAKE(newton_q, n);
#undef TAKE
    if (memory == NULL) return used + 1; /* + 1: never a request for no bytes */
    s->basis = integers, s->rows = integers + N, s->basic = integers + 2 * N, s->kind = integers + 3 * N, s->column = integers + 3 * N + m;
    for (Py_ssize_t i = 0; i < N; i++) s->covering[i] = i >= 2 * n && i < 2 * n + m ? s->gap_covering : 1.0;
    return used;
}

/* The scratch space of s (its sizes set) laid out in new memory, which the caller frees with PyMem_RawFree (NULL where
 * none was allocated); -1 with MemoryError where the sizes are too large or an allocation fails. */
static int allocate(Split *s, double **memory, int64_t **integers) {
    if (s->N > LARGEST_SPLIT || s->n + 3 * s->m > LARGEST_SPLIT) { /* dense N x N blocks: callers refuse far smaller problems */
        PyErr_NoMemory();
        return -1;
    }
    const size_t doubles = lay_out(s, NULL, NULL);
    *memory = PyMem_RawMalloc(doubles * sizeof(double));
    *integers = PyMem_RawMalloc((size_t)(3 * s->N + 2 * s->m + 1) * sizeof(int64_t));
    if (*memory == NULL || *integers == NULL) {
        PyErr_NoMemory();
        return -1;
    }
    lay_out(s, *memory, *integers);
    return 0;
}

/* Take argument `index` as a float, into *value (-1 with the exception set when it is not one). */
static int take_double(PyObject *const *args, int index, double *value) {
    *value = PyFloat_AsDouble(args[index]);
    return *value == -1.0 && PyErr_Occurred() ? -1 : 0;
}

/* The flags, counts and tolerances of solve_split_lcp's arguments into s (-1 with the exception set). */
static int take_options(PyObject *const *args, Split *s, int *exact, long long *max_realignments) {
    *exact = PyObject_IsTrue(args[6]);
    s->free_twist = PyObject_IsTrue(args[7]);
    *max_realignments = PyLong_AsLongLong(args[9]);
    const long long pivots_per_row = PyLong_AsLongLong(args[14]);
    if (*exact < 0 || s->free_twist < 0 || ((*max_realignments == -1 || pivots_per_row == -1) && PyErr_Occurred())) return -1;
    s->pivots_per_row = pivots_per_row;
    if (take_double(args, 8, &s->gap_covering) || take_double(args, 10, &s->dissipation_tol) || take_double(args, 11, &s->mode_tol) ||
        take_double(args, 12, &s->pivot_tol) || take_double(args, 13, &s->feasibility_tol) || take_double(args, 15, &s->cone_roundoff) ||
        take_double(args, 16, &s->newton_damping) || take_double(args, 17, &s->newton_stop))
        return -1;
    return 0;
}

/* The sizes m, d, n (from J), f (frictional) and K (base) into s; ValueError where J, frictional or base has the wrong
 * number of dimensions, or exact cones are asked of 2-D contacts. */
static int take_sizes(PyObject *const *args, Split *s, int exact) {
    const int indices[3] = {0, 4, 5}, ndims[3] = {3, 1, 1};
    Py_ssize_t shapes[3][3] = {{0}};
    for (int k = 0; k < 3; k++) {
        Py_buffer probe;
        if (PyObject_GetBuffer(args[indices[k]], &probe, PyBUF_STRIDES) < 0) return -1;
        const int right = probe.ndim == ndims[k];
        for (int axis = 0; right && axis < ndims[k]; axis++) shapes[k][axis] = probe.shape[axis];
        PyBuffer_Release(&probe);
        if (!right) {
            PyErr_SetString(PyExc_ValueError, k == 0 ? "J must have shape (m, d, n) with d = 2 or 3" : "frictional and base must be one-dimensional");
            return -1;
        }
    }
    s->m = shapes[0][0], s->d = shapes[0][1], s->n = shapes[0][2], s->f = shapes[1][0], s->K = shapes[2][0];
    if (s->d < 2 || s->d > 3) {
        PyErr_SetString(PyExc_ValueError, "J must have shape (m, d, n) with d = 2 or 3");
        return -1;
    }
    if (exact && s->d != 3) {
        PyErr_SetString(PyExc_ValueError, "exact cones need 3-D contacts (d = 3)");
        return -1;
    }
    return 0;
}

static PyObject *solve_split_lcp(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    (void)module;
    if (nargs != 20) {
        PyErr_SetString(PyExc_TypeError,
                        "solve_split_lcp(J, b, mu, g, frictional, base, exact, free_twist, gap_covering, max_realignments, dissipation_tol,"
                        " mode_tol, pivot_tol, feasibility_tol, pivots_per_row, cone_roundoff, newton_damping, newton_stop, q, c) takes 20"
                        " arguments");
        return NULL;
    }
    Split s;
    memset(&s, 0, sizeof s);
    int exact;
    long long max_realignments;
    if (take_options(args, &s, &exact, &max_realignments) < 0 || take_sizes(args, &s, exact) < 0) return NULL;
    const Py_ssize_t m = s.m, d = s.d, n = s.n, f = s.f, K = s.K;
    static const char *names[8] = {"J", "b", "mu", "g", "frictional", "base", "q", "c"};
    const int indices[8] = {0, 1, 2, 3, 4, 5, 18, 19};
    const int ndims[8] = {3, 2, 1, 1, 1, 1, 1, 2};
    const Py_ssize_t shapes[8][3] = {{m, d, n}, {m, d}, {m}, {n}, {f}, {K}, {n}, {m, d}};
    Py_buffer views[8];
    int taken = 0;
    PyObject *result = NULL;
    double *memory = NULL;
    int64_t *integers = NULL;
    for (; taken < 8; taken++) {
        const char *codes = taken == 4 ? "ql" : "d";
        if (take_buffer(args[indices[taken]], &views[taken], names[taken], codes, taken >= 6, ndims[taken], shapes[taken]) < 0) goto done;
    }
    s.J = views[0].buf, s.b = views[1].buf, s.mu = views[2].buf, s.g = views[3].buf, s.frictional = views[4].buf, s.base = views[5].buf;
    for (Py_ssize_t a = 0; a < f; a++)
        if (s.frictional[a] < 0 || s.frictional[a] >= m) {
            PyErr_Format(PyExc_ValueError, "frictional[%zd] = %lld is not a contact index", a, (long long)s.frictional[a]);
            goto done;
        }
    s.N = 2 * n + m + f * K + f;
    if (allocate(&s, &memory, &integers) < 0) goto done;
    SplitResult out;
    Py_BEGIN_ALLOW_THREADS
    out = split_lcp(&s, exact, max_realignments, views[6].buf, views[7].buf);
    Py_END_ALLOW_THREADS
    result = Py_BuildValue("(LLLL)", (long long)out.status, (long long)out.stage, (long long)out.pivots, (long long)out.realignments);
done:
    PyMem_RawFree(memory);
    PyMem_RawFree(integers);
    for (int k = 0; k < taken; k++) PyBuffer_Release(&views[k]);
    return result;
}

static PyObject *exact_newton(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    (void)module;
    if (nargs != 16) {
        PyErr_SetString(PyExc_TypeError, "exact_newton(J, b, mu, g, q, c, depth, patience, one_switch, mode_tol, tol, cone_roundoff,"
                                         " newton_damping, newton_stop, q_out, c_out) takes 16 arguments");
        return NULL;
    }
    Split s;
    memset(&s, 0, sizeof s);
    double depth, tol;
    const long long patience = PyLong_AsLongLong(args[7]);
    if (patience == -1 && PyErr_Occurred()) return NULL;
    const int one_switch = PyObject_IsTrue(args[8]);
    if (one_switch < 0) return NULL;
    if (take_double(args, 6, &depth) || take_double(args, 9, &s.mode_tol) || take_double(args, 10, &tol) ||
        take_double(args, 11, &s.cone_roundoff) || take_double(args, 12, &s.newton_damping) || take_double(args, 13, &s.newton_stop))
        return NULL;
    Py_buffer probe;
    if (PyObject_GetBuffer(args[0], &probe, PyBUF_STRIDES) < 0) return NULL;
    const int right = probe.ndim == 3 && probe.shape[1] == 3;
    if (right) s.m = probe.shape[0], s.d = 3, s.n = probe.shape[2];
    PyBuffer_Release(&probe);
    if (!right) {
        PyErr_SetString(PyExc_ValueError, "J must have shape (m, 3, n)");
        return NULL;
    }
    const Py_ssize_t m = s.m, n = s.n;
    static const char *names[8] = {"J", "b", "mu", "g", "q", "c", "q_out", "c_out"};
    const int ndims[8] = {3, 2, 1, 1, 1, 2, 1, 2};
    const Py_ssize_t shapes[8][3] = {{m, 3, n}, {m, 3}, {m}, {n}, {n}, {m, 3}, {n}, {m, 3}};
    Py_buffer views[8];
    int taken = 0;
    PyObject *result = NULL;
    double *memory = NULL;
    int64_t *integers = NULL;
    const int indices[8] = {0, 1, 2, 3, 4, 5, 14, 15};
    for (; taken < 8; taken++)
        if (take_buffer(args[indices[taken]], &views[taken], names[taken], "d", taken >= 6, ndims[taken], shapes[taken]) < 0) goto done;
    s.J = views[0].buf, s.b = views[1].buf, s.mu = views[2].buf, s.g = views[3].buf;
    s.N = 2 * n + m; /* no edges: the LCP's arrays, which Newton's method does not use, at their smallest */
    if (allocate(&s, &memory, &integers) < 0) goto done;
    int converged;
    Py_BEGIN_ALLOW_THREADS
    converged = newton(&s, views[4].buf, views[5].buf, depth, patience, one_switch, tol);
    double *q_out = views[6].buf, *c_out = views[7].buf;
    for (Py_ssize_t j = 0; j < n; j++) q_out[j] = s.newton_q[j];
    for (Py_ssize_t i = 0; i < m * 3; i++) c_out[i] = s.forces[i];
    Py_END_ALLOW_THREADS
    result = PyBool_FromLong(converged);
done:
    PyMem_RawFree(memory);
    PyMem_RawFree(integers);
    for (int k = 0; k < taken; k++) PyBuffer_Release(&views[k]);
    return result;
}

static PyMethodDef methods[] = {
    {"lemke", (PyCFunction)(void (*)(void))lemke, METH_FASTCALL,
     "lemke(M, q, d, max_pivots, tol, free, z, basis) -> (status, pivots): Lemke's method, the numba kernel's rules;\n"
     "fills z (n,) float64 and basis (n,) int64. See quasistatic.solvers.numerics.lemke."},
    {"fixed_mode_system", (PyCFunction)(void (*)(void))fixed_mode_system, METH_FASTCALL,
     "fixed_mode_system(J, b, mu, g, x, kind, column, residual, jacobian, forces): the fixed-mode laws at x,\n"
     "the numba kernel's loops; fills residual (N,), jacobian (N, N) and forces (m, d). See quasistatic.laws.fixed_modes."},
    {"solve_split_lcp", (PyCFunction)(void (*)(void))solve_split_lcp, METH_FASTCALL,
     "solve_split_lcp(J, b, mu, g, frictional, base, exact, free_twist, gap_covering, max_realignments, dissipation_tol, mode_tol,\n"
     "pivot_tol, feasibility_tol, pivots_per_row, cone_roundoff, newton_damping, newton_stop, q, c) -> (status, stage, pivots, realignments):\n"
     "the fast path's kernel, the numba kernel's steps; fills q (n,) and c (m, d). See quasistatic.solvers.numerics.lcp."},
    {"exact_newton", (PyCFunction)(void (*)(void))exact_newton, METH_FASTCALL,
     "exact_newton(J, b, mu, g, q, c, depth, patience, one_switch, mode_tol, tol, cone_roundoff, newton_damping, newton_stop,"
     " q_out, c_out) -> bool:\n"
     "Newton's method on the exact 3-D fixed-mode laws from (q, c), the numba kernel's steps; fills q_out (n,) and c_out (m, 3).\n"
     "See quasistatic.solvers.numerics.lcp.exact_newton."},
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
    /* what quasistatic/compiled.py checks: a .so built from an older source is not used */
    if (PyModule_AddIntConstant(module, "api_version", 7) < 0) {
        Py_DECREF(module);
        return NULL;
    }
    return module;
}
