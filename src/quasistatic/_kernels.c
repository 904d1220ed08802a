/* Compiled twins of small numba kernels, for installs without numba:
 *
 *   audit_laws(links, contacts, loads, T, f, facets, directions, facet_scale, slide_speed,
 *              sums, u, slips, normal) -> None
 *       The audit's per-contact laws, check/audit.py::_laws_2d and _laws_3d (T's width, 3 or 6,
 *       gives the dimension) loop for loop: the same products and sums in the same order, and
 *       max() as Python's and numba's (a later value replaces the one kept only when greater),
 *       so the results are the kernel's to the bit where both round alike. The last four
 *       arrays are filled.
 *   analyse_frictionless(Jn, bn, g, q, forces, zero, motion_rank, force_rank, orthogonal,
 *                        jacobi_max, slack, support, tight, closed) -> (residual, motion_unique, forces_unique)
 *       solvers/lp.py::_analyse: the optimality residual of a primal-dual pair, the slacks
 *       and contact masks (filled), and the two rank verdicts by the same one-sided Jacobi
 *       rotations as solvers/lp.py::_singular_values (1, 0, or -1 past jacobi_max).
 *   to_world(q, c, frames, units, force, T, forces) -> None
 *       laws/motion.py::_to_world_kernel: physical twists T (bodies, k) and world forces (m, d), filled.
 *   drop_roundoff(values, roundoff) -> None
 *       check/motion.py::_drop_roundoff: values (rows, c) within roundoff (c,) of zero set to 0, in place.
 *   assemble_scene(normals, points, coms, owners, others, twists, origins, places, driven, wrenches, masses,
 *                  gravity, smallest_length, frames, J, b, g_and_scales) -> None
 *       laws/assemble.py::assemble_numpy from the scene's numbers: the movers' point velocities, the scales
 *       (model/scales.py), each contact's frame, rows of J and b, and the loads g; frames, J (zeros on
 *       entry), b and g_and_scales (g, then the origin, length, force and velocity) are filled.
 *   stack_rows(rows, out) -> None
 *       numpy's array() of a list of 1-D float arrays of one width, into out (len(rows), width).
 *   nonnegative_fit(A, keep, b, x) -> residual
 *       solvers/numerics/nnls.py::nonnegative_fit: non-negative least squares on the kept columns of A
 *       (Lawson and Hanson's method, Householder reflections), x (N,) filled; |A x - b| returned.
 *   polygon_vertices(rates, reserve, rows, parallel, skew, slack, vertices) -> count
 *       solvers/numerics/polygon.py::polygon_vertices: the vertices of a polygon of half-planes (the kept rows
 *       of rates . x + reserve >= 0), filled in vertices (pairs, 2); their count, or -1 (unbounded).
 *   closed_rows(E, e, by_rank, rank, orthogonal, zero, sigma, basis, inverse, q0, spread) -> (r, residual_square)
 *       solvers/numerics/closed_set.py::closed_rows: closed rows factored by one-sided Jacobi rotations (singular
 *       values, right singular vectors, the pseudo-inverse truncated to r ranks, q0, spread), filled.
 *   row_bounds(bank, rhs, inverse, q0, directions, rows, slack, reserve, rates) -> None
 *       solvers/numerics/closed_set.py::row_bounds: for the bank rows listed in rows, the best slack at q0 with
 *       every closed row loosened by slack (reserve[j]) and the rates along the free directions (rates[j, c]), filled.
 *   polygon_ball(q0, directions, vertices, seed, spread, same, distinct, center) -> reach
 *       solvers/numerics/polygon.py::polygon_ball: the twists q0 + vertices directions, -1 when all lie in the seed's box,
 *       else the ball around them: center (n,) filled, its radius returned.
 *   fit_or_farkas(A, keep, b, margin, ceiling, independent, x, y, bits) -> outcome
 *       solvers/numerics/nnls.py::fit_or_farkas: nonnegative_fit on the columns whose bits keep (int64 words) sets;
 *       where its residual passes margin, y = b - A x checked as a Farkas vector (the columns it cannot exclude in
 *       bits); else the fit's support in bits. 0: the fit balances, 1: y excludes the kept columns, 2: neither.
 *   audit_rows(normals, points, coms, links, twists, origins, driven, through_joints, mu, rows) -> None
 *       check/audit.py::_read_geometry's contact rows: normal, tangents, arms to the coms, the mover's point
 *       velocity (rigid, or a robot's row of driven), mu; each number as the Python loop computes it; rows filled.
 *
 * The Python C API and buffers only (every array C-contiguous, no numpy headers), so setuptools
 * alone builds it; quasistatic/compiled.py wraps it. Shapes and indices are checked
 * (ValueError, never a read or write out of bounds); the GIL is released while it computes.
 * Products are not fused into multiply-adds (numba does not fuse them either).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

#if defined(__clang__)
#pragma clang fp contract(off)
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off")
#endif

/* Python's and numba's max(kept, value): the value replaces the kept one only when greater. */
static inline double greater(double kept, double value) { return value > kept ? value : kept; }

/* ---------------------------------------------------------------- buffers */

enum { FLOATS, INTEGERS, BOOLEANS };

/* Whether a buffer holds the native items of `type`: float64, int64, or numpy's one-byte bool. */
static int has_items(const Py_buffer *view, int type) {
    const char *format = view->format ? view->format : "B";
    if (*format == '@' || *format == '=' || *format == '<') format++;
    if (format[0] == '\0' || format[1] != '\0') return 0;
    if (type == BOOLEANS) return view->itemsize == 1 && format[0] == '?';
    return view->itemsize == 8 && strchr(type == FLOATS ? "d" : "ql", format[0]) != NULL;
}

/* Argument `arg` as a C-contiguous buffer of `type`, `ndim` dimensions; a shape entry of -1
 * takes the buffer's own (read back through `shape`). Returns 0, or -1 with ValueError set. */
static int take(PyObject *arg, Py_buffer *view, const char *name, int type, int writable, int ndim, Py_ssize_t *shape) {
    static const char *items[3] = {"float64", "int64", "bool"};
    const int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(arg, view, flags) < 0) {
        /* not contiguous, or read-only where it is filled (numpy says so by BufferError or ValueError) */
        if (PyErr_ExceptionMatches(PyExc_BufferError) || PyErr_ExceptionMatches(PyExc_ValueError)) {
            PyErr_Clear();
            PyErr_Format(PyExc_ValueError, "%s must be a C-contiguous%s %s array", name, writable ? ", writable" : "", items[type]);
        }
        return -1;
    }
    int same = view->ndim == ndim;
    for (int k = 0; same && k < ndim; k++) {
        if (shape[k] < 0) shape[k] = view->shape[k];
        same = view->shape[k] == shape[k];
    }
    if (!has_items(view, type)) {
        PyErr_Format(PyExc_ValueError, "%s must be a C-contiguous %s array", name, items[type]);
    } else if (!same) {
        PyErr_Format(PyExc_ValueError, "%s must have %d dimensions, shaped as the other arguments", name, ndim);
    } else {
        return 0;
    }
    PyBuffer_Release(view);
    return -1;
}

/* Up to 16 argument buffers taken in order; `release` frees those taken so far. */
typedef struct {
    Py_buffer views[16];
    int taken;
} Buffers;

static int take_next(Buffers *b, PyObject *arg, const char *name, int type, int writable, int ndim, Py_ssize_t *shape) {
    if (take(arg, &b->views[b->taken], name, type, writable, ndim, shape) < 0) return -1;
    b->taken++;
    return 0;
}

static void release(Buffers *b) {
    for (int k = 0; k < b->taken; k++) PyBuffer_Release(&b->views[k]);
    b->taken = 0;
}

static int take_floats(PyObject *arg, double *value, const char *name) {
    *value = PyFloat_AsDouble(arg);
    if (*value == -1.0 && PyErr_Occurred()) {
        PyErr_Format(PyExc_TypeError, "%s must be a float", name);
        return -1;
    }
    return 0;
}

/* ---------------------------------------------------------------- the audit's laws */

/* Columns of sums, as check/audit.py names them. */
enum { LINEAR, ANGULAR, CONE, PENETRATION, NORMAL_POWER, SHORTFALL, SUPPLIED, DISSIPATED, RAISED, CHECK, MISALIGN, SUMS };

/* The audit's arrays (row-major): links (m, 2), contacts (m, w), loads and T (bodies, k), f (m, d),
 * facets and directions (K, 2); out: sums (11,), u and slips (m, d), normal (m, 3). */
typedef struct {
    Py_ssize_t m, bodies, edges;
    const int64_t *links;
    const double *contacts, *loads, *T, *f, *facets, *directions;
    double facet_scale, slide_speed;
    double *sums, *u, *slips, *normal, *totals;
} Laws;

/* What both dimensions' loops accumulate over the contacts. */
typedef struct {
    double cone, penetration, normal_power, shortfall, supplied, dissipated, check, misalign;
} Running;

static void laws_2d(const Laws *L, Running *r) {
    for (Py_ssize_t i = 0; i < L->m; i++) {
        const int64_t b = L->links[2 * i], o = L->links[2 * i + 1];
        const double *c = L->contacts + 11 * i, *fi = L->f + 2 * i;
        const double nx = c[0], ny = c[1], tx = c[2], ty = c[3], rbx = c[4], rby = c[5], rox = c[6], roy = c[7];
        const double mvx = c[8], mvy = c[9], mu = c[10], fx = fi[0], fy = fi[1];
        const double *t = L->T + 3 * b;
        double ux = t[0] - t[2] * rby, uy = t[1] + t[2] * rbx;
        double *total = L->totals + 3 * b;
        total[0] += fx;
        total[1] += fy;
        total[2] += rbx * fy - rby * fx;
        if (o >= 0) {
            t = L->T + 3 * o;
            ux = ux - (t[0] - t[2] * roy);
            uy = uy - (t[1] + t[2] * rox);
            total = L->totals + 3 * o;
            total[0] -= fx;
            total[1] -= fy;
            total[2] -= rox * fy - roy * fx;
        } else {
            ux = ux - mvx;
            uy = uy - mvy;
            r->supplied += fx * mvx + fy * mvy;
        }
        const double f_n = fx * nx + fy * ny, f_t = fx * tx + fy * ty;
        const double u_n = ux * nx + uy * ny, u_t = ux * tx + uy * ty;
        const double radius = mu * greater(f_n, 0.0);
        r->cone = greater(greater(r->cone, -f_n), fabs(f_t) - radius);
        r->penetration = greater(r->penetration, -u_n);
        r->normal_power = greater(r->normal_power, fabs(f_n * u_n));
        r->shortfall = greater(r->shortfall, radius * fabs(u_t) + f_t * u_t);
        r->dissipated -= fx * ux + fy * uy - f_n * u_n;
        r->check += fx + fy + ux + uy;
        const double sx = ux - u_n * nx, sy = uy - u_n * ny;
        L->u[2 * i] = ux, L->u[2 * i + 1] = uy;
        L->slips[2 * i] = sx, L->slips[2 * i + 1] = sy;
        double *normal = L->normal + 3 * i;
        normal[0] = u_n, normal[1] = sqrt(sx * sx + sy * sy), normal[2] = f_n;
    }
}

/* The friction set's excursion and the slip's support of a 3-D pyramid (its facets and edge directions). */
static void pyramid(const Laws *L, double f_1, double f_2, double u_1, double u_2, double radius, double *outside, double *support) {
    *outside = -INFINITY;
    *support = -INFINITY;
    for (Py_ssize_t k = 0; k < L->edges; k++) {
        const double *facet = L->facets + 2 * k, *direction = L->directions + 2 * k;
        *outside = greater(*outside, facet[0] * f_1 + facet[1] * f_2);
        *support = greater(*support, -(direction[0] * u_1 + direction[1] * u_2));
    }
    *outside -= radius * L->facet_scale;
}

static void laws_3d(const Laws *L, Running *r) {
    for (Py_ssize_t i = 0; i < L->m; i++) {
        const int64_t b = L->links[2 * i], o = L->links[2 * i + 1];
        const double *c = L->contacts + 19 * i, *fi = L->f + 3 * i;
        const double nx = c[0], ny = c[1], nz = c[2], ax = c[3], ay = c[4], az = c[5], bx = c[6], by = c[7], bz = c[8];
        const double rx = c[9], ry = c[10], rz = c[11], sx = c[12], sy = c[13], sz = c[14];
        const double mx = c[15], my = c[16], mz = c[17], mu = c[18], fx = fi[0], fy = fi[1], fz = fi[2];
        const double *t = L->T + 6 * b;
        double ux = t[0] + t[4] * rz - t[5] * ry, uy = t[1] + t[5] * rx - t[3] * rz, uz = t[2] + t[3] * ry - t[4] * rx;
        double *total = L->totals + 6 * b;
        total[0] += fx;
        total[1] += fy;
        total[2] += fz;
        total[3] += ry * fz - rz * fy;
        total[4] += rz * fx - rx * fz;
        total[5] += rx * fy - ry * fx;
        if (o >= 0) {
            t = L->T + 6 * o;
            ux -= t[0] + t[4] * sz - t[5] * sy;
            uy -= t[1] + t[5] * sx - t[3] * sz;
            uz -= t[2] + t[3] * sy - t[4] * sx;
            total = L->totals + 6 * o;
            total[0] -= fx;
            total[1] -= fy;
            total[2] -= fz;
            total[3] -= sy * fz - sz * fy;
            total[4] -= sz * fx - sx * fz;
            total[5] -= sx * fy - sy * fx;
        } else {
            ux = ux - mx, uy = uy - my, uz = uz - mz;
            r->supplied += fx * mx + fy * my + fz * mz;
        }
        const double f_n = fx * nx + fy * ny + fz * nz;
        const double f_1 = fx * ax + fy * ay + fz * az, f_2 = fx * bx + fy * by + fz * bz;
        const double u_n = ux * nx + uy * ny + uz * nz;
        const double u_1 = ux * ax + uy * ay + uz * az, u_2 = ux * bx + uy * by + uz * bz;
        const double radius = mu * greater(f_n, 0.0);
        double outside, support;
        if (L->edges > 0) {
            pyramid(L, f_1, f_2, u_1, u_2, radius, &outside, &support);
        } else {
            outside = sqrt(f_1 * f_1 + f_2 * f_2) - radius;
            support = sqrt(u_1 * u_1 + u_2 * u_2);
            if (support > L->slide_speed) { /* sliding: the friction must be -mu f_n slip/|slip| exactly */
                const double e_1 = f_1 + radius * u_1 / support, e_2 = f_2 + radius * u_2 / support;
                r->misalign = greater(r->misalign, sqrt(e_1 * e_1 + e_2 * e_2));
            }
        }
        r->cone = greater(greater(r->cone, -f_n), outside);
        r->penetration = greater(r->penetration, -u_n);
        r->normal_power = greater(r->normal_power, fabs(f_n * u_n));
        r->shortfall = greater(r->shortfall, radius * support + f_1 * u_1 + f_2 * u_2);
        r->dissipated -= fx * ux + fy * uy + fz * uz - f_n * u_n;
        r->check += fx + fy + fz + ux + uy + uz;
        const double px = ux - u_n * nx, py = uy - u_n * ny, pz = uz - u_n * nz;
        L->u[3 * i] = ux, L->u[3 * i + 1] = uy, L->u[3 * i + 2] = uz;
        L->slips[3 * i] = px, L->slips[3 * i + 1] = py, L->slips[3 * i + 2] = pz;
        double *normal = L->normal + 3 * i;
        normal[0] = u_n, normal[1] = sqrt(px * px + py * py + pz * pz), normal[2] = f_n;
    }
}

/* The kernel in dimension `dim`: the totals start at the loads, the contacts' loop, then _finish's
 * largest unbalanced force and moment, the power against the loads and the finiteness check. */
static void audit(const Laws *L, int dim) {
    const Py_ssize_t k = dim == 2 ? 3 : 6;
    memcpy(L->totals, L->loads, (size_t)(L->bodies * k) * sizeof(double));
    Running r = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    if (dim == 2)
        laws_2d(L, &r);
    else
        laws_3d(L, &r);
    double linear = 0.0, angular = 0.0, raised = 0.0, check = r.check;
    for (Py_ssize_t a = 0; a < L->bodies; a++) {
        for (Py_ssize_t j = 0; j < k; j++) {
            const double total = L->totals[a * k + j];
            check += total;
            if (j < dim)
                linear = greater(linear, fabs(total));
            else
                angular = greater(angular, fabs(total));
            raised -= L->loads[a * k + j] * L->T[a * k + j];
        }
    }
    double *sums = L->sums;
    for (int s = 0; s < SUMS; s++) sums[s] = 0.0;
    sums[LINEAR] = linear, sums[ANGULAR] = angular, sums[RAISED] = raised, sums[CHECK] = check + raised;
    sums[CONE] = r.cone, sums[PENETRATION] = r.penetration, sums[NORMAL_POWER] = r.normal_power, sums[SHORTFALL] = r.shortfall;
    if (dim == 3) sums[MISALIGN] = r.misalign;
    sums[SUPPLIED] = r.supplied, sums[DISSIPATED] = r.dissipated;
}

/* Whether every contact's body is a body and its other a body or -1 (a mover). */
static int links_fit(const int64_t *links, Py_ssize_t m, Py_ssize_t bodies) {
    for (Py_ssize_t i = 0; i < m; i++) {
        const int64_t b = links[2 * i], o = links[2 * i + 1];
        if (b < 0 || b >= bodies || o < -1 || o >= bodies) {
            PyErr_Format(PyExc_ValueError, "links[%zd] = (%lld, %lld) names a body outside 0..%zd", i, (long long)b, (long long)o, bodies - 1);
            return 0;
        }
    }
    return 1;
}

static PyObject *audit_laws(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    (void)module;
    if (nargs != 13) {
        PyErr_SetString(PyExc_TypeError,
                        "audit_laws(links, contacts, loads, T, f, facets, directions, facet_scale, slide_speed, sums, u, slips, normal) "
                        "takes 13 arguments");
        return NULL;
    }
    double facet_scale, slide_speed;
    if (take_floats(args[7], &facet_scale, "facet_scale") < 0 || take_floats(args[8], &slide_speed, "slide_speed") < 0) return NULL;
    Buffers b = {.taken = 0};
    Py_ssize_t twists[2] = {-1, -1};
    PyObject *result = NULL;
    double *totals = NULL;
    if (take_next(&b, args[3], "T", FLOATS, 0, 2, twists) < 0) goto done;
    const Py_ssize_t bodies = twists[0], k = twists[1];
    if (k != 3 && k != 6) {
        PyErr_SetString(PyExc_ValueError, "T must have shape (bodies, 3) or (bodies, 6)");
        goto done;
    }
    const int dim = k == 3 ? 2 : 3;
    Py_ssize_t links[2] = {-1, 2}, contacts[2] = {-1, 1 + dim * (dim + 3)}, loads[2] = {bodies, k}, f[2] = {-1, dim};
    Py_ssize_t facets[2] = {-1, 2}, directions[2] = {-1, 2}, sums[1] = {SUMS}, u[2] = {-1, dim}, slips[2] = {-1, dim};
    Py_ssize_t normal[2] = {-1, 3};
    if (take_next(&b, args[0], "links", INTEGERS, 0, 2, links) < 0) goto done;
    const Py_ssize_t m = links[0];
    contacts[0] = f[0] = u[0] = slips[0] = normal[0] = m;
    if (take_next(&b, args[1], "contacts", FLOATS, 0, 2, contacts) < 0 || take_next(&b, args[2], "loads", FLOATS, 0, 2, loads) < 0 ||
        take_next(&b, args[4], "f", FLOATS, 0, 2, f) < 0 || take_next(&b, args[5], "facets", FLOATS, 0, 2, facets) < 0)
        goto done;
    directions[0] = facets[0];
    if (take_next(&b, args[6], "directions", FLOATS, 0, 2, directions) < 0 || take_next(&b, args[9], "sums", FLOATS, 1, 1, sums) < 0 ||
        take_next(&b, args[10], "u", FLOATS, 1, 2, u) < 0 || take_next(&b, args[11], "slips", FLOATS, 1, 2, slips) < 0 ||
        take_next(&b, args[12], "normal", FLOATS, 1, 2, normal) < 0)
        goto done;
    const int64_t *link_values = b.views[1].buf;
    if (!links_fit(link_values, m, bodies)) goto done;
    totals = PyMem_RawMalloc((size_t)(bodies * k + 1) * sizeof(double)); /* +1: never a request for 0 bytes */
    if (totals == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    const Laws L = {m, bodies, facets[0], link_values, b.views[2].buf, b.views[3].buf, b.views[0].buf, b.views[4].buf,
                    b.views[5].buf, b.views[6].buf, facet_scale, slide_speed, b.views[7].buf, b.views[8].buf, b.views[9].buf,
                    b.views[10].buf, totals};
    Py_BEGIN_ALLOW_THREADS
    audit(&L, dim);
    Py_END_ALLOW_THREADS
    result = Py_NewRef(Py_None);
done:
    PyMem_RawFree(totals);
    release(&b);
    return result;
}

/* ---------------------------------------------------------------- the frictionless LP's analysis */

/* The rotation that makes two columns orthogonal (squared norms alpha and beta, product gamma): its tan in the
 * kernels' overflow-free form (see solvers/lp.py::_singular_values), then cos and sin. */
static inline void jacobi_rotation(double alpha, double beta, double gamma, double *cos, double *sin) {
    const double diff = beta - alpha;
    const double sign = diff == 0.0 || (diff > 0.0) == (gamma > 0.0) ? 1.0 : -1.0;
    const double t = sign * 2.0 * fabs(gamma) / (fabs(diff) + hypot(2.0 * gamma, diff));
    *cos = 1.0 / sqrt(1.0 + t * t);
    *sin = *cos * t;
}

/* Singular values of the (rows, cols) matrix W, column-major, rows >= cols, by one-sided Jacobi rotations
 * (Hestenes), solvers/lp.py::_singular_values sweep for sweep; W is rotated in place, sigma (cols) filled. */
static void singular_values(double *W, Py_ssize_t rows, Py_ssize_t cols, double orthogonal, double *sigma) {
    for (int sweep = 0; sweep < 60; sweep++) {
        int rotated = 0;
        for (Py_ssize_t p = 0; p + 1 < cols; p++) {
            for (Py_ssize_t q = p + 1; q < cols; q++) {
                double *wp = W + p * rows, *wq = W + q * rows;
                double alpha = 0.0, beta = 0.0, gamma = 0.0;
                for (Py_ssize_t i = 0; i < rows; i++) {
                    alpha += wp[i] * wp[i];
                    beta += wq[i] * wq[i];
                    gamma += wp[i] * wq[i];
                }
                if (gamma == 0.0 || fabs(gamma) <= orthogonal * sqrt(alpha * beta)) continue;
                rotated = 1;
                double cos, sin;
                jacobi_rotation(alpha, beta, gamma, &cos, &sin);
                for (Py_ssize_t i = 0; i < rows; i++) {
                    const double a = wp[i], b = wq[i];
                    wp[i] = cos * a - sin * b;
                    wq[i] = sin * a + cos * b;
                }
            }
        }
        if (!rotated) break;
    }
    for (Py_ssize_t j = 0; j < cols; j++) {
        double total = 0.0;
        for (Py_ssize_t i = 0; i < rows; i++) total += W[j * rows + i] * W[j * rows + i];
        sigma[j] = sqrt(total);
    }
}

/* The frictionless analysis' arrays: Jn (m, n) row-major, bn (m,), g (n,), q (n,), forces (m,);
 * out: slack (m,), the masks (m,); work: room for one (m, n) matrix and its n singular values. */
typedef struct {
    Py_ssize_t m, n;
    const double *Jn, *bn, *g, *q, *forces;
    double orthogonal;
    Py_ssize_t jacobi_max;
    double *slack;
    char *support, *tight, *closed;
    double *work, *sigma;
} Pair;

/* _full_rank on the rows of Jn where `rows` is set (count of them): 1 when `rank` singular values
 * exceed tol, else 0; -1 when the matrix is too large for Jacobi rotations. */
static int full_rank(const Pair *P, const char *rows, Py_ssize_t count, double tol, Py_ssize_t rank) {
    const Py_ssize_t n = P->n;
    if (count == 0 || n == 0) return rank == 0;
    if ((count < n ? count : n) > P->jacobi_max) return -1;
    /* W column-major: A itself when it is tall (a column of A a column of W), else A^T (a row of A a column). */
    const int tall = count >= n;
    Py_ssize_t r = 0;
    for (Py_ssize_t i = 0; i < P->m; i++) {
        if (!rows[i]) continue;
        for (Py_ssize_t j = 0; j < n; j++) {
            if (tall)
                P->work[j * count + r] = P->Jn[i * n + j];
            else
                P->work[r * n + j] = P->Jn[i * n + j];
        }
        r++;
    }
    const Py_ssize_t wrows = tall ? count : n, wcols = tall ? n : count;
    singular_values(P->work, wrows, wcols, P->orthogonal, P->sigma);
    Py_ssize_t above = 0;
    for (Py_ssize_t j = 0; j < wcols; j++) above += P->sigma[j] > tol;
    return above == rank;
}

/* solvers/lp.py::_analyse: returns the residual (infinite when a value is not finite) and the two verdicts. */
static double analyse(const Pair *P, double zero, double motion_rank, double force_rank, int *motion_unique, int *forces_unique) {
    const Py_ssize_t m = P->m, n = P->n;
    double residual = 0.0;
    for (Py_ssize_t i = 0; i < m; i++) {
        double s = -P->bn[i];
        for (Py_ssize_t j = 0; j < n; j++) s += P->Jn[i * n + j] * P->q[j];
        P->slack[i] = s;
        residual = greater(greater(greater(residual, -s), -P->forces[i]), fabs(P->forces[i] * s));
    }
    for (Py_ssize_t j = 0; j < n; j++) {
        double e = P->g[j];
        for (Py_ssize_t i = 0; i < m; i++) e += P->Jn[i * n + j] * P->forces[i];
        residual = greater(residual, fabs(e));
    }
    int finite = 1;
    Py_ssize_t k = 0, n_support = 0, loose_support = 0;
    for (Py_ssize_t i = 0; i < m; i++) {
        P->support[i] = P->forces[i] > zero;
        P->closed[i] = P->slack[i] <= zero;
        P->tight[i] = P->closed[i] && !P->support[i];
        k += P->closed[i];
        n_support += P->support[i];
        loose_support += P->support[i] && !P->closed[i];
        finite = finite && isfinite(P->forces[i]) && isfinite(P->slack[i]);
    }
    for (Py_ssize_t j = 0; j < n; j++) finite = finite && isfinite(P->q[j]);
    *motion_unique = *forces_unique = 0;
    if (!finite) return INFINITY;
    *forces_unique = k == 0 ? 1 : (k > n ? 0 : full_rank(P, P->closed, k, force_rank, k));
    if (*forces_unique == 1 && loose_support == 0) /* supporting rows among independent closed ones */
        *motion_unique = n_support == n;
    else
        *motion_unique = n_support < n ? 0 : full_rank(P, P->support, n_support, motion_rank, n);
    return residual;
}

static PyObject *analyse_frictionless(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    (void)module;
    if (nargs != 14) {
        PyErr_SetString(PyExc_TypeError,
                        "analyse_frictionless(Jn, bn, g, q, forces, zero, motion_rank, force_rank, orthogonal, jacobi_max, "
                        "slack, support, tight, closed) takes 14 arguments");
        return NULL;
    }
    double tols[4];
    static const char *tol_names[4] = {"zero", "motion_rank", "force_rank", "orthogonal"};
    for (int k = 0; k < 4; k++)
        if (take_floats(args[5 + k], &tols[k], tol_names[k]) < 0) return NULL;
    const Py_ssize_t jacobi_max = PyLong_AsSsize_t(args[9]);
    if (jacobi_max == -1 && PyErr_Occurred()) return NULL;
    Buffers b = {.taken = 0};
    Py_ssize_t shape[2] = {-1, -1};
    PyObject *result = NULL;
    double *work = NULL;
    if (take_next(&b, args[0], "Jn", FLOATS, 0, 2, shape) < 0) goto done;
    const Py_ssize_t m = shape[0], n = shape[1];
    Py_ssize_t rows[1] = {m}, cols[1] = {n};
    /* the vectors after Jn: the inputs, then what is filled (slack, then the three masks) */
    static const char *names[8] = {"bn", "g", "q", "forces", "slack", "support", "tight", "closed"};
    static const int positions[8] = {1, 2, 3, 4, 10, 11, 12, 13};
    for (int k = 0; k < 8; k++) {
        Py_ssize_t *size = k == 1 || k == 2 ? cols : rows;
        const int type = k < 5 ? FLOATS : BOOLEANS;
        if (take_next(&b, args[positions[k]], names[k], type, k >= 4, 1, size) < 0) goto done;
    }
    work = PyMem_RawMalloc((size_t)(m * n + n + 1) * sizeof(double)); /* W and its singular values (at most n); +1: never 0 bytes */
    if (work == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    const Pair P = {m, n, b.views[0].buf, b.views[1].buf, b.views[2].buf, b.views[3].buf, b.views[4].buf, tols[3], jacobi_max,
                    b.views[5].buf, b.views[6].buf, b.views[7].buf, b.views[8].buf, work, work + m * n};
    int motion_unique, forces_unique;
    double residual;
    Py_BEGIN_ALLOW_THREADS
    residual = analyse(&P, tols[0], tols[1], tols[2], &motion_unique, &forces_unique);
    Py_END_ALLOW_THREADS
    result = Py_BuildValue("(dii)", residual, motion_unique, forces_unique);
done:
    PyMem_RawFree(work);
    release(&b);
    return result;
}

/* ---------------------------------------------------------------- small conversions on every answer's path */

static PyObject *to_world(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    (void)module;
    if (nargs != 7) {
        PyErr_SetString(PyExc_TypeError, "to_world(q, c, frames, units, force, T, forces) takes 7 arguments");
        return NULL;
    }
    double force;
    if (take_floats(args[4], &force, "force") < 0) return NULL;
    Buffers b = {.taken = 0};
    Py_ssize_t q[1] = {-1}, c[2] = {-1, -1}, units[1] = {-1};
    PyObject *result = NULL;
    if (take_next(&b, args[0], "q", FLOATS, 0, 1, q) < 0 || take_next(&b, args[1], "c", FLOATS, 0, 2, c) < 0 ||
        take_next(&b, args[3], "units", FLOATS, 0, 1, units) < 0)
        goto done;
    const Py_ssize_t size = q[0], m = c[0], d = c[1], k = units[0];
    if (k == 0 || size % k != 0) {
        PyErr_SetString(PyExc_ValueError, "q must hold whole twists: its length a multiple of units' (not 0)");
        goto done;
    }
    Py_ssize_t frames[3] = {m, d, d}, T[2] = {size / k, k}, forces[2] = {m, d};
    if (take_next(&b, args[2], "frames", FLOATS, 0, 3, frames) < 0 || take_next(&b, args[5], "T", FLOATS, 1, 2, T) < 0 ||
        take_next(&b, args[6], "forces", FLOATS, 1, 2, forces) < 0)
        goto done;
    const double *qv = b.views[0].buf, *cv = b.views[1].buf, *uv = b.views[2].buf, *fv = b.views[3].buf;
    double *Tv = b.views[4].buf, *out = b.views[5].buf;
    /* laws/motion.py::_to_world_kernel: each twist entry times its unit; each force the frame's rows
     * weighted by the contact-frame components, summed in order, then times the force scale. */
    for (Py_ssize_t r = 0; r < size; r++) Tv[r] = qv[r] * uv[r % k];
    for (Py_ssize_t i = 0; i < m; i++) {
        for (Py_ssize_t j = 0; j < d; j++) {
            double total = 0.0;
            for (Py_ssize_t s = 0; s < d; s++) total += cv[i * d + s] * fv[(i * d + s) * d + j];
            out[i * d + j] = total * force;
        }
    }
    result = Py_NewRef(Py_None);
done:
    release(&b);
    return result;
}

static PyObject *drop_roundoff(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    (void)module;
    if (nargs != 2) {
        PyErr_SetString(PyExc_TypeError, "drop_roundoff(values, roundoff) takes 2 arguments");
        return NULL;
    }
    Buffers b = {.taken = 0};
    Py_ssize_t values[2] = {-1, -1}, roundoff[1] = {-1};
    PyObject *result = NULL;
    if (take_next(&b, args[0], "values", FLOATS, 1, 2, values) < 0) goto done;
    roundoff[0] = values[1];
    if (take_next(&b, args[1], "roundoff", FLOATS, 0, 1, roundoff) < 0) goto done;
    double *v = b.views[0].buf;
    const double *limit = b.views[1].buf;
    /* check/motion.py::_drop_roundoff: entries within their column's round-off of zero set to 0 (NaN kept) */
    for (Py_ssize_t r = 0; r < values[0] * values[1]; r++)
        if (fabs(v[r]) <= limit[r % values[1]]) v[r] = 0.0;
    result = Py_NewRef(Py_None);
done:
    release(&b);
    return result;
}

/* ---------------------------------------------------------------- gathering a scene's vectors */

/* stack_rows(rows, out): each item of the sequence `rows` (a 1-D C-contiguous float64 buffer of out's width)
 * copied into its row of out (len(rows), width); numpy's array() of a list of small arrays costs ~10x more. */
static PyObject *stack_rows(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    (void)module;
    if (nargs != 2) {
        PyErr_SetString(PyExc_TypeError, "stack_rows(rows, out) takes 2 arguments");
        return NULL;
    }
    PyObject *items = PySequence_Fast(args[0], "rows must be a sequence");
    if (items == NULL) return NULL;
    Buffers b = {.taken = 0};
    PyObject *result = NULL;
    const Py_ssize_t count = PySequence_Fast_GET_SIZE(items);
    Py_ssize_t out[2] = {count, -1};
    if (take_next(&b, args[1], "out", FLOATS, 1, 2, out) < 0) goto done;
    double *target = b.views[0].buf;
    PyObject **row = PySequence_Fast_ITEMS(items);
    for (Py_ssize_t i = 0; i < count; i++) {
        Py_ssize_t width[1] = {out[1]};
        Py_buffer view;
        if (take(row[i], &view, "a row", FLOATS, 0, 1, width) < 0) goto done;
        memcpy(target + i * out[1], view.buf, (size_t)out[1] * sizeof(double));
        PyBuffer_Release(&view);
    }
    result = Py_NewRef(Py_None);
done:
    release(&b);
    Py_DECREF(items);
    return result;
}

/* ---------------------------------------------------------------- assembly */

static inline void cross3(const double *a, const double *b, double *out) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* A scene's numbers as model/kinematics.py::mover_parts and laws/assemble.py gather them (row-major). */
typedef struct {
    Py_ssize_t m, d, k, bodies;
    const double *normals, *points, *coms, *twists, *origins, *places, *driven, *wrenches, *masses, *gravity;
    const int64_t *owners, *others;
    double smallest_length;
} SceneNumbers;

/* model/kinematics.py::mover_point_velocities for contact i: driven + v + omega x (place - origin). */
static void mover_velocity(const SceneNumbers *S, Py_ssize_t i, double *out) {
    const Py_ssize_t d = S->d;
    const double *twist = S->twists + i * S->k, *place = S->places + i * d, *origin = S->origins + i * d, *driven = S->driven + i * d;
    double r[3], spin[3];
    for (Py_ssize_t j = 0; j < d; j++) r[j] = place[j] - origin[j];
    if (d == 2) { /* omega (-r_y, r_x), as the numpy twin multiplies it */
        spin[0] = twist[2] * r[1] * -1.0;
        spin[1] = twist[2] * r[0] * 1.0;
    } else {
        cross3(twist + 3, r, spin);
    }
    for (Py_ssize_t j = 0; j < d; j++) out[j] = driven[j] + twist[j] + spin[j];
}

/* Body a's load (k,): model/scales.py::_loads, the wrench plus mass times gravity. */
static void body_load(const SceneNumbers *S, Py_ssize_t a, double *load) {
    for (Py_ssize_t j = 0; j < S->k; j++) load[j] = S->wrenches[a * S->k + j];
    for (Py_ssize_t j = 0; j < S->d; j++) load[j] += S->masses[a] * S->gravity[j];
}

static double square_sum(const double *v, Py_ssize_t n) {
    double total = v[0] * v[0];
    for (Py_ssize_t j = 1; j < n; j++) total += v[j] * v[j];
    return total;
}

/* model/scales.py::scene_scales: origin (d,), then length, force, velocity, in `out` (d + 3,); each sum in
 * order, as NumPy adds along these axes. `velocities` (m, d) are the movers' point velocities. */
static void scene_scales(const SceneNumbers *S, const double *velocities, double *out) {
    const Py_ssize_t d = S->d, count = S->m + S->bodies;
    double *origin = out, place[3], load[6];
    for (Py_ssize_t j = 0; j < d; j++) origin[j] = S->points[j];
    for (Py_ssize_t p = 1; p < count; p++)
        for (Py_ssize_t j = 0; j < d; j++) origin[j] += p < S->m ? S->points[p * d + j] : S->coms[(p - S->m) * d + j];
    for (Py_ssize_t j = 0; j < d; j++) origin[j] /= (double)count;
    double widest = 0.0, largest = 0.0;
    for (Py_ssize_t p = 0; p < count; p++) {
        const double *x = p < S->m ? S->points + p * d : S->coms + (p - S->m) * d;
        for (Py_ssize_t j = 0; j < d; j++) place[j] = x[j] - origin[j];
        widest = greater(widest, square_sum(place, d));
        for (Py_ssize_t j = 0; j < d; j++) largest = greater(largest, fabs(x[j]));
    }
    double length = sqrt(widest);
    if (length == 0.0) /* every point coincides: only their distance from the world origin sets a size */
        length = S->smallest_length <= largest && largest <= 1.0 / S->smallest_length ? largest : 1.0;
    double force = 0.0, torque = 0.0, speed = 0.0;
    for (Py_ssize_t a = 0; a < S->bodies; a++) {
        body_load(S, a, load);
        force = greater(force, sqrt(square_sum(load, d)));
        torque = greater(torque, sqrt(square_sum(load + d, S->k - d)));
    }
    force = greater(force, torque / length);
    for (Py_ssize_t i = 0; i < S->m; i++) speed = greater(speed, square_sum(velocities + i * d, d));
    const double velocity = sqrt(speed);
    out[d] = length, out[d + 1] = force == 0.0 ? 1.0 : force, out[d + 2] = velocity == 0.0 ? 1.0 : velocity;
}

/* model/kinematics.py::contact_frames for one normal n (d = 2 or 3): rows t (t1, t2), then n. */
static void contact_frame(const double *n, Py_ssize_t d, double *frame) {
    if (d == 2) {
        frame[0] = n[1], frame[1] = -n[0], frame[2] = n[0], frame[3] = n[1];
        return;
    }
    int axis = 0; /* np.argmin(|n|): the first of equal smallest entries */
    for (int j = 1; j < 3; j++)
        if (fabs(n[j]) < fabs(n[axis])) axis = j;
    const double e[3] = {axis == 0 ? 1.0 : 0.0, axis == 1 ? 1.0 : 0.0, axis == 2 ? 1.0 : 0.0};
    double t1[3];
    cross3(n, e, t1);
    const double norm = sqrt(square_sum(t1, 3));
    for (int j = 0; j < 3; j++) frame[j] = t1[j] / norm;
    cross3(n, frame, frame + 3);
    for (int j = 0; j < 3; j++) frame[6 + j] = n[j];
}

/* laws/assemble.py::_twist_rows for one contact: each frame row's velocity per unit twist of a body whose
 * com is `arm` away from the point, added into its block `J` of the contact's rows (negated for the other body). */
static void add_twist_rows(const double *frame, const double *arm, Py_ssize_t d, int negate, double *J, Py_ssize_t width) {
    const Py_ssize_t k = d == 2 ? 3 : 6;
    for (Py_ssize_t s = 0; s < d; s++) {
        const double *f = frame + s * d;
        double row[6];
        for (Py_ssize_t j = 0; j < d; j++) row[j] = f[j];
        if (d == 2) row[2] = arm[0] * f[1] - arm[1] * f[0];
        else cross3(arm, f, row + 3);
        for (Py_ssize_t j = 0; j < k; j++) J[s * width + j] += negate ? -row[j] : row[j];
    }
}

/* laws/assemble.py::assemble_numpy for contact i: its frame, rows of J and b, in the scales' units. */
static void contact_laws(const SceneNumbers *S, Py_ssize_t i, const double *scales, const double *velocity, double *frame, double *J,
                         double *b) {
    const Py_ssize_t d = S->d, width = S->k * S->bodies;
    const double *origin = scales, length = scales[d];
    double point[3], arm[3];
    contact_frame(S->normals + i * d, d, frame);
    for (Py_ssize_t j = 0; j < d; j++) point[j] = (S->points[i * d + j] - origin[j]) / length;
    const int64_t partners[2] = {S->owners[i], S->others[i]};
    for (int side = 0; side < 2 && partners[side] >= 0; side++) { /* the other free body's motion counts against */
        for (Py_ssize_t j = 0; j < d; j++) arm[j] = point[j] - (S->coms[partners[side] * d + j] - origin[j]) / length;
        add_twist_rows(frame, arm, d, side, J + partners[side] * S->k, width);
    }
    for (Py_ssize_t s = 0; s < d; s++) { /* the mover's point velocity in the frame, summed in order */
        double total = frame[s * d] * velocity[0];
        for (Py_ssize_t j = 1; j < d; j++) total += frame[s * d + j] * velocity[j];
        b[s] = total / scales[d + 2];
    }
}

static PyObject *assemble_scene(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    (void)module;
    if (nargs != 17) {
        PyErr_SetString(PyExc_TypeError,
                        "assemble_scene(normals, points, coms, owners, others, twists, origins, places, driven, wrenches, masses, "
                        "gravity, smallest_length, frames, J, b, g_and_scales) takes 17 arguments");
        return NULL;
    }
    SceneNumbers S = {0};
    if (take_floats(args[12], &S.smallest_length, "smallest_length") < 0) return NULL;
    Buffers b = {.taken = 0};
    Py_ssize_t normals[2] = {-1, -1};
    PyObject *result = NULL;
    if (take_next(&b, args[0], "normals", FLOATS, 0, 2, normals) < 0) goto done;
    S.m = normals[0], S.d = normals[1], S.k = S.d == 2 ? 3 : 6;
    if ((S.d != 2 && S.d != 3) || S.m == 0) {
        PyErr_SetString(PyExc_ValueError, "normals must be (m, 2) or (m, 3) with m >= 1");
        goto done;
    }
    const Py_ssize_t m = S.m, d = S.d, k = S.k;
    Py_ssize_t points[2] = {m, d}, coms[2] = {-1, d}, owners[1] = {m}, others[1] = {m}, twists[2] = {m, k}, origins[2] = {m, d};
    Py_ssize_t places[2] = {m, d}, driven[2] = {m, d};
    if (take_next(&b, args[1], "points", FLOATS, 0, 2, points) < 0 || take_next(&b, args[2], "coms", FLOATS, 0, 2, coms) < 0 ||
        take_next(&b, args[3], "owners", INTEGERS, 0, 1, owners) < 0 || take_next(&b, args[4], "others", INTEGERS, 0, 1, others) < 0 ||
        take_next(&b, args[5], "twists", FLOATS, 0, 2, twists) < 0 || take_next(&b, args[6], "origins", FLOATS, 0, 2, origins) < 0 ||
        take_next(&b, args[7], "places", FLOATS, 0, 2, places) < 0 || take_next(&b, args[8], "driven", FLOATS, 0, 2, driven) < 0)
        goto done;
    S.bodies = coms[0];
    Py_ssize_t wrenches[2] = {S.bodies, k}, masses[1] = {S.bodies}, gravity[1] = {d};
    Py_ssize_t frames[3] = {m, d, d}, J[3] = {m, d, k * S.bodies}, bv[2] = {m, d}, out[1] = {S.bodies * k + d + 3};
    if (take_next(&b, args[9], "wrenches", FLOATS, 0, 2, wrenches) < 0 || take_next(&b, args[10], "masses", FLOATS, 0, 1, masses) < 0 ||
        take_next(&b, args[11], "gravity", FLOATS, 0, 1, gravity) < 0 || take_next(&b, args[13], "frames", FLOATS, 1, 3, frames) < 0 ||
        take_next(&b, args[14], "J", FLOATS, 1, 3, J) < 0 || take_next(&b, args[15], "b", FLOATS, 1, 2, bv) < 0 ||
        take_next(&b, args[16], "g_and_scales", FLOATS, 1, 1, out) < 0)
        goto done;
    S.normals = b.views[0].buf, S.points = b.views[1].buf, S.coms = b.views[2].buf, S.owners = b.views[3].buf, S.others = b.views[4].buf;
    S.twists = b.views[5].buf, S.origins = b.views[6].buf, S.places = b.views[7].buf, S.driven = b.views[8].buf;
    S.wrenches = b.views[9].buf, S.masses = b.views[10].buf, S.gravity = b.views[11].buf;
    for (Py_ssize_t i = 0; i < m; i++) {
        if (S.owners[i] < 0 || S.owners[i] >= S.bodies || S.others[i] < -1 || S.others[i] >= S.bodies) {
            PyErr_Format(PyExc_ValueError, "contact %zd names body %lld or other %lld outside 0..%zd", i, (long long)S.owners[i],
                         (long long)S.others[i], S.bodies - 1);
            goto done;
        }
    }
    double *velocities = PyMem_RawMalloc((size_t)(m * d) * sizeof(double));
    if (velocities == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    double *frame = b.views[12].buf, *Jv = b.views[13].buf, *bo = b.views[14].buf, *g = b.views[15].buf, *scales = g + S.bodies * k;
    Py_BEGIN_ALLOW_THREADS
    for (Py_ssize_t i = 0; i < m; i++) mover_velocity(&S, i, velocities + i * d);
    scene_scales(&S, velocities, scales);
    const double length = scales[d], force = scales[d + 1];
    for (Py_ssize_t i = 0; i < m; i++)
        contact_laws(&S, i, scales, velocities + i * d, frame + i * d * d, Jv + i * d * k * S.bodies, bo + i * d);
    for (Py_ssize_t a = 0; a < S.bodies; a++) { /* laws/assemble.py: each load over the wrench units F, then F L */
        body_load(&S, a, g + a * k);
        for (Py_ssize_t j = 0; j < k; j++) g[a * k + j] /= j < d ? force : force * length;
    }
    Py_END_ALLOW_THREADS
    PyMem_RawFree(velocities);
    result = Py_NewRef(Py_None);
done:
    release(&b);
    return result;
}

/* ---------------------------------------------------------------- non-negative least squares */

/* solvers/numerics/nnls.py::_passive_least_squares: z[:p] from the p passive columns of A (m, N) by Householder
 * reflections; 0 when a column's part off the span of those before it is below `independent` of its norm. */
static int passive_least_squares(Py_ssize_t m, Py_ssize_t N, const double *A, const int64_t *passive, Py_ssize_t p,
                                 const double *b, double independent, double *R, double *qb, double *z) {
    for (Py_ssize_t c = 0; c < p; c++)
        for (Py_ssize_t i = 0; i < m; i++) R[i * m + c] = A[i * N + passive[c]];
    for (Py_ssize_t i = 0; i < m; i++) qb[i] = b[i];
    for (Py_ssize_t c = 0; c < p; c++) {
        double tail = 0.0;
        for (Py_ssize_t i = c; i < m; i++) tail += R[i * m + c] * R[i * m + c];
        tail = sqrt(tail);
        double whole = tail * tail;
        for (Py_ssize_t i = 0; i < c; i++) whole += R[i * m + c] * R[i * m + c];
        if (!(tail > independent * sqrt(whole))) return 0;
        double head = R[c * m + c] >= 0.0 ? -tail : tail;
        R[c * m + c] = R[c * m + c] - head;
        double scale = 0.0;
        for (Py_ssize_t i = c; i < m; i++) scale += R[i * m + c] * R[i * m + c];
        for (Py_ssize_t cc = c + 1; cc < p; cc++) {
            double s = 0.0;
            for (Py_ssize_t i = c; i < m; i++) s += R[i * m + c] * R[i * m + cc];
            s = 2.0 * s / scale;
            for (Py_ssize_t i = c; i < m; i++) R[i * m + cc] -= s * R[i * m + c];
        }
        double s = 0.0;
        for (Py_ssize_t i = c; i < m; i++) s += R[i * m + c] * qb[i];
        s = 2.0 * s / scale;
        for (Py_ssize_t i = c; i < m; i++) qb[i] -= s * R[i * m + c];
        R[c * m + c] = head;
    }
    for (Py_ssize_t c = p - 1; c >= 0; c--) {
        double value = qb[c];
        for (Py_ssize_t cc = c + 1; cc < p; cc++) value -= R[c * m + cc] * z[cc];
        z[c] = value / R[c * m + c];
    }
    return 1;
}

/* solvers/numerics/nnls.py::nonnegative_fit, loop for loop; work: 4 m + m m doubles, m int64, N chars. */
static double nonnegative_fit_loops(Py_ssize_t m, Py_ssize_t N, const double *A, const char *keep, const double *b,
                                    double independent, double *x, double *work, int64_t *passive, char *rejected) {
    double *r = work, *qb = work + m, *z = work + 2 * m, *R = work + 3 * m;
    for (Py_ssize_t k = 0; k < N; k++) { x[k] = 0.0; rejected[k] = 0; }
    Py_ssize_t p = 0;
    for (Py_ssize_t i = 0; i < m; i++) r[i] = b[i];
    for (Py_ssize_t round = 0; round < 3 * N + 1; round++) {
        double best = 0.0;
        Py_ssize_t j = -1;
        for (Py_ssize_t k = 0; k < N; k++) {
            if (keep[k] && x[k] == 0.0 && !rejected[k]) {
                double w = 0.0;
                for (Py_ssize_t i = 0; i < m; i++) w += A[i * N + k] * r[i];
                if (w > best) { best = w; j = k; }
            }
        }
        if (j < 0 || p == m) break;
        passive[p++] = j;
        int entered = 0;
        while (1) {
            if (!passive_least_squares(m, N, A, passive, p, b, independent, R, qb, z)) break;
            if (!entered) {
                if (z[p - 1] <= 0.0) break;
                entered = 1;
                for (Py_ssize_t k = 0; k < N; k++) rejected[k] = 0;
            }
            double alpha = 2.0;
            Py_ssize_t leaving = -1;
            for (Py_ssize_t c = 0; c < p; c++) {
                if (z[c] <= 0.0) {
                    double step = x[passive[c]] / (x[passive[c]] - z[c]);
                    if (step < alpha) { alpha = step; leaving = c; }
                }
            }
            if (leaving < 0) {
                for (Py_ssize_t c = 0; c < p; c++) x[passive[c]] = z[c];
                break;
            }
            Py_ssize_t kept = 0;
            for (Py_ssize_t c = 0; c < p; c++) {
                int64_t k = passive[c];
                x[k] = x[k] + alpha * (z[c] - x[k]);
                if (x[k] > 0.0 && c != leaving) passive[kept++] = k;
                else x[k] = 0.0;
            }
            p = kept;
        }
        if (!entered) { p--; rejected[j] = 1; }
        for (Py_ssize_t i = 0; i < m; i++) {
            r[i] = b[i];
            for (Py_ssize_t c = 0; c < p; c++) r[i] -= A[i * N + passive[c]] * x[passive[c]];
        }
    }
    double total = 0.0;
    for (Py_ssize_t i = 0; i < m; i++) {
        double value = -b[i];
        for (Py_ssize_t k = 0; k < N; k++)
            if (x[k] != 0.0) value += A[i * N + k] * x[k];
        total += value * value;
    }
    return sqrt(total);
}

static PyObject *nonnegative_fit(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    (void)module;
    if (nargs != 5) {
        PyErr_SetString(PyExc_TypeError, "nonnegative_fit(A, keep, b, x, independent) takes 5 arguments");
        return NULL;
    }
    Buffers b = {.taken = 0};
    Py_ssize_t A[2] = {-1, -1}, keep[1] = {-1}, rhs[1] = {-1}, x[1] = {-1};
    double independent, residual = 0.0;
    PyObject *result = NULL;
    if (take_next(&b, args[0], "A", FLOATS, 0, 2, A) < 0) goto done;
    keep[0] = x[0] = A[1];
    rhs[0] = A[0];
    if (take_next(&b, args[1], "keep", BOOLEANS, 0, 1, keep) < 0) goto done;
    if (take_next(&b, args[2], "b", FLOATS, 0, 1, rhs) < 0) goto done;
    if (take_next(&b, args[3], "x", FLOATS, 1, 1, x) < 0) goto done;
    if (take_floats(args[4], &independent, "independent") < 0) goto done;
    Py_ssize_t m = A[0], N = A[1];
    double *work = PyMem_Malloc(sizeof(double) * (size_t)(4 * m + m * m + 1));
    int64_t *passive = PyMem_Malloc(sizeof(int64_t) * (size_t)(m + 1));
    char *rejected = PyMem_Malloc((size_t)(N + 1));
    if (work == NULL || passive == NULL || rejected == NULL) {
        PyErr_NoMemory();
    } else {
        Py_BEGIN_ALLOW_THREADS
        residual = nonnegative_fit_loops(m, N, b.views[0].buf, b.views[1].buf, b.views[2].buf, independent, b.views[3].buf,
                                         work, passive, rejected);
        Py_END_ALLOW_THREADS
        result = PyFloat_FromDouble(residual);
    }
    PyMem_Free(work);
    PyMem_Free(passive);
    PyMem_Free(rejected);
done:
    release(&b);
    return result;
}

/* ---------------------------------------------------------------- a polygon's vertices */

static const double PI = 3.141592653589793; /* Python's math.pi (M_PI is POSIX, not C) */

/* solvers/numerics/polygon.py::polygon_vertices, loop for loop; work: 5 R doubles. */
static Py_ssize_t polygon_vertices_loops(Py_ssize_t total, const double *rates, const double *reserve, const char *rows,
                                         double parallel, double skew, double slack, double *vertices, double *work) {
    double *s0 = work, *s1 = work + total, *offset = work + 2 * total, *norm = work + 3 * total, *angles = work + 4 * total;
    Py_ssize_t P = 0;
    for (Py_ssize_t k = 0; k < total; k++) {
        if (!rows[k]) continue;
        double size = sqrt(rates[2 * k] * rates[2 * k] + rates[2 * k + 1] * rates[2 * k + 1]);
        if (size == 0.0) {
            if (reserve[k] < 0.0) return 0;
            continue;
        }
        s0[P] = rates[2 * k];
        s1[P] = rates[2 * k + 1];
        offset[P] = reserve[k];
        norm[P] = size;
        P++;
    }
    if (P < 3) return -1;
    for (Py_ssize_t k = 0; k < P; k++) angles[k] = atan2(s1[k], s0[k]);
    for (Py_ssize_t k = 1; k < P; k++) {
        double value = angles[k];
        Py_ssize_t at = k;
        while (at > 0 && angles[at - 1] > value) {
            angles[at] = angles[at - 1];
            at--;
        }
        angles[at] = value;
    }
    double widest = angles[0] + 2.0 * PI - angles[P - 1];
    for (Py_ssize_t k = 1; k < P; k++) widest = greater(widest, angles[k] - angles[k - 1]);
    if (widest >= PI - skew) return -1;
    for (Py_ssize_t i = 0; i < P; i++)
        for (Py_ssize_t j = i + 1; j < P; j++) {
            double sine = fabs(s0[i] * s1[j] - s1[i] * s0[j]) / (norm[i] * norm[j]);
            if (sine < skew && sine > parallel) return -1;
        }
    Py_ssize_t count = 0;
    for (Py_ssize_t i = 0; i < P; i++)
        for (Py_ssize_t j = i + 1; j < P; j++) {
            double det = s0[i] * s1[j] - s1[i] * s0[j];
            if (!(fabs(det) / (norm[i] * norm[j]) >= skew)) continue;
            double x = (s1[i] * offset[j] - s1[j] * offset[i]) / det;
            double y = (s0[j] * offset[i] - s0[i] * offset[j]) / det;
            double size = sqrt(x * x + y * y);
            int inside = 1;
            for (Py_ssize_t k = 0; k < P; k++)
                if (s0[k] * x + s1[k] * y + offset[k] < -(slack * (norm[k] * size + fabs(offset[k])))) {
                    inside = 0;
                    break;
                }
            if (inside) {
                vertices[2 * count] = x;
                vertices[2 * count + 1] = y;
                count++;
            }
        }
    return count;
}

static PyObject *polygon_vertices(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    (void)module;
    if (nargs != 7) {
        PyErr_SetString(PyExc_TypeError, "polygon_vertices(rates, reserve, rows, parallel, skew, slack, vertices) takes 7 arguments");
        return NULL;
    }
    Buffers b = {.taken = 0};
    Py_ssize_t rates[2] = {-1, 2}, reserve[1] = {-1}, rows[1] = {-1}, vertices[2] = {-1, 2};
    double parallel, skew, slack;
    PyObject *result = NULL;
    if (take_next(&b, args[0], "rates", FLOATS, 0, 2, rates) < 0) goto done;
    reserve[0] = rows[0] = rates[0];
    if (take_next(&b, args[1], "reserve", FLOATS, 0, 1, reserve) < 0) goto done;
    if (take_next(&b, args[2], "rows", BOOLEANS, 0, 1, rows) < 0) goto done;
    if (take_next(&b, args[6], "vertices", FLOATS, 1, 2, vertices) < 0) goto done;
    if (take_floats(args[3], &parallel, "parallel") < 0 || take_floats(args[4], &skew, "skew") < 0 ||
        take_floats(args[5], &slack, "slack") < 0)
        goto done;
    Py_ssize_t total = rates[0], kept = 0;
    const char *chosen = b.views[2].buf;
    for (Py_ssize_t k = 0; k < total; k++) kept += chosen[k] != 0;
    if (vertices[0] < kept * (kept - 1) / 2) {
        PyErr_SetString(PyExc_ValueError, "vertices must have a row for every pair of the rows kept");
        goto done;
    }
    double *work = PyMem_Malloc(sizeof(double) * (size_t)(5 * total + 1));
    if (work == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    Py_ssize_t count;
    Py_BEGIN_ALLOW_THREADS
    count = polygon_vertices_loops(total, b.views[0].buf, b.views[1].buf, chosen, parallel, skew, slack, b.views[3].buf, work);
    Py_END_ALLOW_THREADS
    PyMem_Free(work);
    result = PyLong_FromSsize_t(count);
done:
    release(&b);
    return result;
}

/* ---------------------------------------------------------------- a closed set's factors */

/* solvers/numerics/closed_set.py::closed_rows, loop for loop: E (k, n), e (k,); sigma (n,), basis (n, n), inverse
 * (n, k), q0 (n,), spread (n,) filled; work: k n + n n + n doubles, n integers and n flags. Returns r, the square in
 * *square (0 and 0.0 when no rank is kept). */
static Py_ssize_t closed_rows_loops(Py_ssize_t k, Py_ssize_t n, const double *E, const double *e, int by_rank, double rank,
                                    double orthogonal, double zero, double *sigma, double *basis, double *inverse, double *q0,
                                    double *spread, double *square, double *W, double *V, double *norms, Py_ssize_t *order,
                                    char *taken) {
    memcpy(W, E, sizeof(double) * (size_t)(k * n));
    for (Py_ssize_t i = 0; i < n; i++)
        for (Py_ssize_t j = 0; j < n; j++) V[i * n + j] = i == j ? 1.0 : 0.0;
    double negligible = 0.0; /* a null direction's column, in round-off: no pair with it turns */
    for (Py_ssize_t i = 0; i < k; i++)
        for (Py_ssize_t j = 0; j < n; j++) negligible += E[i * n + j] * E[i * n + j];
    negligible *= orthogonal * orthogonal;
    for (int sweep = 0; sweep < 60; sweep++) {
        int rotated = 0;
        for (Py_ssize_t p = 0; p + 1 < n; p++)
            for (Py_ssize_t q = p + 1; q < n; q++) {
                double alpha = 0.0, beta = 0.0, gamma = 0.0;
                for (Py_ssize_t i = 0; i < k; i++) {
                    alpha += W[i * n + p] * W[i * n + p];
                    beta += W[i * n + q] * W[i * n + q];
                    gamma += W[i * n + p] * W[i * n + q];
                }
                if (gamma == 0.0 || fabs(gamma) <= orthogonal * sqrt(alpha * beta) || fmin(alpha, beta) <= negligible) continue;
                rotated = 1;
                double cos, sin;
                jacobi_rotation(alpha, beta, gamma, &cos, &sin);
                for (Py_ssize_t i = 0; i < k; i++) {
                    const double a = W[i * n + p], b = W[i * n + q];
                    W[i * n + p] = cos * a - sin * b;
                    W[i * n + q] = sin * a + cos * b;
                }
                for (Py_ssize_t i = 0; i < n; i++) {
                    const double a = V[i * n + p], b = V[i * n + q];
                    V[i * n + p] = cos * a - sin * b;
                    V[i * n + q] = sin * a + cos * b;
                }
            }
        if (!rotated) break;
    }
    for (Py_ssize_t j = 0; j < n; j++) {
        double total = 0.0;
        for (Py_ssize_t i = 0; i < k; i++) total += W[i * n + j] * W[i * n + j];
        norms[j] = sqrt(total);
        taken[j] = 0;
    }
    for (Py_ssize_t slot = 0; slot < n; slot++) {
        Py_ssize_t best = -1;
        for (Py_ssize_t j = 0; j < n; j++)
            if (!taken[j] && (best < 0 || norms[j] > norms[best])) best = j;
        taken[best] = 1;
        order[slot] = best;
    }
    const Py_ssize_t full = k < n ? k : n;
    Py_ssize_t r = 0;
    for (Py_ssize_t slot = 0; slot < n; slot++) {
        const Py_ssize_t j = order[slot];
        sigma[slot] = slot < full ? norms[j] : 0.0;
        for (Py_ssize_t i = 0; i < n; i++) basis[slot * n + i] = V[i * n + j];
        if (slot < full && (!by_rank || norms[j] > rank)) r = slot + 1;
    }
    *square = 0.0;
    if (r == 0 || sigma[r - 1] <= rank) return 0;
    for (Py_ssize_t i = 0; i < n; i++)
        for (Py_ssize_t c = 0; c < k; c++) {
            double value = 0.0;
            for (Py_ssize_t slot = 0; slot < r; slot++) {
                const Py_ssize_t j = order[slot];
                value += V[i * n + j] * (W[c * n + j] / (norms[j] * norms[j]));
            }
            inverse[i * k + c] = value;
        }
    for (Py_ssize_t i = 0; i < n; i++) {
        double value = 0.0, size = 0.0;
        for (Py_ssize_t c = 0; c < k; c++) {
            value += inverse[i * k + c] * e[c];
            size += fabs(inverse[i * k + c]);
        }
        q0[i] = value;
        spread[i] = zero * size;
    }
    for (Py_ssize_t c = 0; c < k; c++) {
        double value = 0.0;
        for (Py_ssize_t i = 0; i < n; i++) value += E[c * n + i] * q0[i];
        *square += (value - e[c]) * (value - e[c]);
    }
    return r;
}

static PyObject *closed_rows(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    (void)module;
    if (nargs != 11) {
        PyErr_SetString(PyExc_TypeError, "closed_rows(E, e, by_rank, rank, orthogonal, zero, sigma, basis, inverse, q0, spread) takes 11 arguments");
        return NULL;
    }
    Buffers b = {.taken = 0};
    Py_ssize_t E[2] = {-1, -1}, e[1], sigma[1], basis[2], inverse[2], q0[1], spread[1];
    double rank, orthogonal, zero;
    PyObject *result = NULL;
    if (take_next(&b, args[0], "E", FLOATS, 0, 2, E) < 0) goto done;
    e[0] = inverse[1] = E[0];
    sigma[0] = basis[0] = basis[1] = inverse[0] = q0[0] = spread[0] = E[1];
    int by_rank = PyObject_IsTrue(args[2]);
    if (by_rank < 0 || take_next(&b, args[1], "e", FLOATS, 0, 1, e) < 0 || take_next(&b, args[6], "sigma", FLOATS, 1, 1, sigma) < 0 ||
        take_next(&b, args[7], "basis", FLOATS, 1, 2, basis) < 0 || take_next(&b, args[8], "inverse", FLOATS, 1, 2, inverse) < 0 ||
        take_next(&b, args[9], "q0", FLOATS, 1, 1, q0) < 0 || take_next(&b, args[10], "spread", FLOATS, 1, 1, spread) < 0 ||
        take_floats(args[3], &rank, "rank") < 0 || take_floats(args[4], &orthogonal, "orthogonal") < 0 ||
        take_floats(args[5], &zero, "zero") < 0)
        goto done;
    Py_ssize_t k = E[0], n = E[1];
    double *work = PyMem_Malloc(sizeof(double) * (size_t)(k * n + n * n + n + 1) + sizeof(Py_ssize_t) * (size_t)(n + 1) + (size_t)(n + 1));
    if (work == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    Py_ssize_t *order = (Py_ssize_t *)(work + k * n + n * n + n + 1);
    char *taken = (char *)(order + n + 1);
    Py_ssize_t r;
    double square;
    Py_BEGIN_ALLOW_THREADS
    r = closed_rows_loops(k, n, b.views[0].buf, b.views[1].buf, by_rank, rank, orthogonal, zero, b.views[2].buf, b.views[3].buf,
                          b.views[4].buf, b.views[5].buf, b.views[6].buf, &square, work, work + k * n, work + k * n + n * n, order, taken);
    Py_END_ALLOW_THREADS
    PyMem_Free(work);
    result = Py_BuildValue("(nd)", r, square);
done:
    release(&b);
    return result;
}

/* ---------------------------------------------------------------- a closed set's bank rows */

/* solvers/numerics/closed_set.py::row_bounds, loop for loop: bank (R, n), rhs (R,), inverse (n, k), q0 (n,),
 * directions (f, n), rows (I,); reserve (R,) and rates (R, 2) filled at the rows listed. */
static void row_bounds_loops(Py_ssize_t n, Py_ssize_t k, Py_ssize_t free, Py_ssize_t count, const double *bank, const double *rhs,
                             const double *inverse, const double *q0, const double *directions, const int64_t *rows, double slack,
                             double *reserve, double *rates) {
    for (Py_ssize_t t = 0; t < count; t++) {
        const int64_t j = rows[t];
        const double *row = bank + j * n;
        double value = 0.0, reach = 0.0;
        for (Py_ssize_t l = 0; l < n; l++) value += row[l] * q0[l];
        for (Py_ssize_t i = 0; i < k; i++) {
            double product = 0.0;
            for (Py_ssize_t l = 0; l < n; l++) product += row[l] * inverse[l * k + i];
            reach += fabs(product);
        }
        reserve[j] = value + slack * reach - rhs[j] + slack;
        for (Py_ssize_t c = 0; c < free; c++) {
            double rate = 0.0;
            for (Py_ssize_t l = 0; l < n; l++) rate += row[l] * directions[c * n + l];
            rates[2 * j + c] = rate;
        }
    }
}

static PyObject *row_bounds(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    (void)module;
    if (nargs != 9) {
        PyErr_SetString(PyExc_TypeError, "row_bounds(bank, rhs, inverse, q0, directions, rows, slack, reserve, rates) takes 9 arguments");
        return NULL;
    }
    Buffers b = {.taken = 0};
    Py_ssize_t bank[2] = {-1, -1}, rhs[1], inverse[2] = {-1, -1}, q0[1], directions[2] = {-1, -1}, rows[1] = {-1}, reserve[1],
               rates[2];
    double slack;
    PyObject *result = NULL;
    if (take_next(&b, args[0], "bank", FLOATS, 0, 2, bank) < 0) goto done;
    rhs[0] = reserve[0] = rates[0] = bank[0];
    inverse[0] = q0[0] = bank[1];
    rates[1] = 2;
    if (take_next(&b, args[1], "rhs", FLOATS, 0, 1, rhs) < 0 || take_next(&b, args[2], "inverse", FLOATS, 0, 2, inverse) < 0 ||
        take_next(&b, args[3], "q0", FLOATS, 0, 1, q0) < 0 || take_next(&b, args[4], "directions", FLOATS, 0, 2, directions) < 0 ||
        take_next(&b, args[5], "rows", INTEGERS, 0, 1, rows) < 0 || take_next(&b, args[7], "reserve", FLOATS, 1, 1, reserve) < 0 ||
        take_next(&b, args[8], "rates", FLOATS, 1, 2, rates) < 0 || take_floats(args[6], &slack, "slack") < 0)
        goto done;
    if (directions[1] != bank[1] || directions[0] > 2) {
        PyErr_SetString(PyExc_ValueError, "directions must be (f, n) with f <= 2 and n the bank's columns");
        goto done;
    }
    const int64_t *chosen = b.views[5].buf;
    for (Py_ssize_t t = 0; t < rows[0]; t++)
        if (chosen[t] < 0 || chosen[t] >= bank[0]) {
            PyErr_SetString(PyExc_ValueError, "rows must index the bank's rows");
            goto done;
        }
    Py_BEGIN_ALLOW_THREADS
    row_bounds_loops(bank[1], inverse[1], directions[0], rows[0], b.views[0].buf, b.views[1].buf, b.views[2].buf, b.views[3].buf,
                     b.views[4].buf, chosen, slack, b.views[6].buf, b.views[7].buf);
    Py_END_ALLOW_THREADS
    result = Py_NewRef(Py_None);
done:
    release(&b);
    return result;
}

/* ---------------------------------------------------------------- a polygon of twists' ball */

/* solvers/numerics/polygon.py::polygon_ball, loop for loop: q0 (n,), directions (2, n), vertices (V, 2), seed (n,) or
 * NULL, spread (n,); center (n,) filled; work: V n doubles. */
static double polygon_ball_loops(Py_ssize_t n, Py_ssize_t V, const double *q0, const double *directions, const double *vertices,
                                 const double *seed, const double *spread, double same, double distinct, double *center, double *work) {
    for (Py_ssize_t v = 0; v < V; v++)
        for (Py_ssize_t l = 0; l < n; l++)
            work[v * n + l] = q0[l] + (vertices[2 * v] * directions[l] + vertices[2 * v + 1] * directions[n + l]);
    if (seed != NULL) {
        double farthest = 0.0, widest = 0.0;
        for (Py_ssize_t l = 0; l < n; l++) {
            double offset = 0.0;
            for (Py_ssize_t v = 0; v < V; v++) offset = greater(offset, fabs(work[v * n + l] - seed[l]));
            farthest = greater(farthest, offset);
            widest = greater(widest, offset + spread[l]);
        }
        if (farthest <= 0.5 * same && widest <= 0.5 * distinct) return -1.0;
    }
    for (Py_ssize_t l = 0; l < n; l++) {
        double low = work[l], high = work[l];
        for (Py_ssize_t v = 1; v < V; v++) {
            double value = work[v * n + l];
            if (value < low) low = value;
            if (value > high) high = value;
        }
        center[l] = 0.5 * (low + high);
    }
    double reach = 0.0;
    for (Py_ssize_t v = 0; v < V; v++) {
        double square = 0.0;
        for (Py_ssize_t l = 0; l < n; l++) {
            double offset = work[v * n + l] - center[l];
            square += offset * offset;
        }
        reach = greater(reach, square);
    }
    return sqrt(reach);
}

static PyObject *polygon_ball(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    (void)module;
    if (nargs != 8) {
        PyErr_SetString(PyExc_TypeError, "polygon_ball(q0, directions, vertices, seed, spread, same, distinct, center) takes 8 arguments");
        return NULL;
    }
    Buffers b = {.taken = 0};
    Py_ssize_t q0[1] = {-1}, directions[2] = {2, -1}, vertices[2] = {-1, 2}, seed[1] = {-1}, spread[1], center[1];
    double same, distinct;
    PyObject *result = NULL;
    if (take_next(&b, args[0], "q0", FLOATS, 0, 1, q0) < 0) goto done;
    directions[1] = spread[0] = center[0] = q0[0];
    if (take_next(&b, args[1], "directions", FLOATS, 0, 2, directions) < 0 || take_next(&b, args[2], "vertices", FLOATS, 0, 2, vertices) < 0 ||
        take_next(&b, args[3], "seed", FLOATS, 0, 1, seed) < 0 || take_next(&b, args[4], "spread", FLOATS, 0, 1, spread) < 0 ||
        take_next(&b, args[7], "center", FLOATS, 1, 1, center) < 0 || take_floats(args[5], &same, "same") < 0 ||
        take_floats(args[6], &distinct, "distinct") < 0)
        goto done;
    if (seed[0] != 0 && seed[0] != q0[0]) {
        PyErr_SetString(PyExc_ValueError, "seed must be shaped as q0, or empty (no seed)");
        goto done;
    }
    if (vertices[0] < 1) {
        PyErr_SetString(PyExc_ValueError, "vertices must hold a vertex");
        goto done;
    }
    Py_ssize_t n = q0[0], V = vertices[0];
    double *work = PyMem_Malloc(sizeof(double) * (size_t)(V * n + 1));
    if (work == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    double reach;
    const double *chosen_seed = seed[0] ? b.views[3].buf : NULL;
    Py_BEGIN_ALLOW_THREADS
    reach = polygon_ball_loops(n, V, b.views[0].buf, b.views[1].buf, b.views[2].buf, chosen_seed, b.views[4].buf, same, distinct,
                               b.views[5].buf, work);
    Py_END_ALLOW_THREADS
    PyMem_Free(work);
    result = PyFloat_FromDouble(reach);
done:
    release(&b);
    return result;
}

/* ---------------------------------------------------------------- a force fit, or a Farkas vector */

enum { FIT_BALANCES, FIT_EXCLUDED, FIT_CANDIDATE };

/* solvers/numerics/nnls.py::fit_or_farkas, loop for loop: the fit on the columns whose bits `keep` (words) sets,
 * then its residual's Farkas check; x, y and bits filled; work as nonnegative_fit_loops's, and N chars for the mask. */
static int fit_or_farkas_loops(Py_ssize_t m, Py_ssize_t N, Py_ssize_t W, const double *A, const int64_t *keep, const double *b,
                               double margin, double ceiling, double independent, double *x, double *y, int64_t *bits,
                               double *work, int64_t *passive, char *rejected, char *mask) {
    for (Py_ssize_t k = 0; k < N; k++) mask[k] = (char)(((uint64_t)keep[k >> 6] >> (k & 63)) & 1);
    double residual = nonnegative_fit_loops(m, N, A, mask, b, independent, x, work, passive, rejected);
    if (residual > margin) {
        double toward = 0.0, square = 0.0;
        for (Py_ssize_t i = 0; i < m; i++) {
            double s = 0.0;
            for (Py_ssize_t k = 0; k < N; k++) s += A[i * N + k] * x[k];
            y[i] = b[i] - s;
            toward += b[i] * y[i];
            square += y[i] * y[i];
        }
        double reserve = toward - margin * sqrt(square);
        if (reserve > 0.0) {
            int64_t met = 0;
            for (Py_ssize_t w = 0; w < W; w++) bits[w] = 0;
            for (Py_ssize_t k = 0; k < N; k++) {
                double s = 0.0;
                for (Py_ssize_t i = 0; i < m; i++) s += A[i * N + k] * y[i];
                if (s * ceiling >= reserve) bits[k >> 6] |= (int64_t)((uint64_t)1 << (k & 63));
            }
            for (Py_ssize_t w = 0; w < W; w++) met |= bits[w] & keep[w];
            if (!met) return FIT_EXCLUDED;
        }
    }
    for (Py_ssize_t w = 0; w < W; w++) bits[w] = 0;
    for (Py_ssize_t k = 0; k < N; k++)
        if (x[k] > 0.0) bits[k >> 6] |= (int64_t)((uint64_t)1 << (k & 63));
    return residual <= margin ? FIT_BALANCES : FIT_CANDIDATE;
}

static PyObject *fit_or_farkas(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    (void)module;
    if (nargs != 9) {
        PyErr_SetString(PyExc_TypeError, "fit_or_farkas(A, keep, b, margin, ceiling, independent, x, y, bits) takes 9 arguments");
        return NULL;
    }
    Buffers b = {.taken = 0};
    Py_ssize_t A[2] = {-1, -1}, keep[1] = {-1}, rhs[1] = {-1}, x[1] = {-1}, y[1] = {-1}, bits[1] = {-1};
    double margin, ceiling, independent;
    PyObject *result = NULL;
    if (take_next(&b, args[0], "A", FLOATS, 0, 2, A) < 0) goto done;
    keep[0] = bits[0] = (A[1] + 63) / 64;
    rhs[0] = y[0] = A[0];
    x[0] = A[1];
    if (take_next(&b, args[1], "keep", INTEGERS, 0, 1, keep) < 0) goto done;
    if (take_next(&b, args[2], "b", FLOATS, 0, 1, rhs) < 0) goto done;
    if (take_floats(args[3], &margin, "margin") < 0 || take_floats(args[4], &ceiling, "ceiling") < 0 ||
        take_floats(args[5], &independent, "independent") < 0)
        goto done;
    if (take_next(&b, args[6], "x", FLOATS, 1, 1, x) < 0) goto done;
    if (take_next(&b, args[7], "y", FLOATS, 1, 1, y) < 0) goto done;
    if (take_next(&b, args[8], "bits", INTEGERS, 1, 1, bits) < 0) goto done;
    Py_ssize_t m = A[0], N = A[1];
    double *work = PyMem_Malloc(sizeof(double) * (size_t)(4 * m + m * m + 1));
    int64_t *passive = PyMem_Malloc(sizeof(int64_t) * (size_t)(m + 1));
    char *chars = PyMem_Malloc((size_t)(2 * N + 1));
    if (work == NULL || passive == NULL || chars == NULL) {
        PyErr_NoMemory();
    } else {
        int outcome;
        Py_BEGIN_ALLOW_THREADS
        outcome = fit_or_farkas_loops(m, N, keep[0], b.views[0].buf, b.views[1].buf, b.views[2].buf, margin, ceiling, independent,
                                      b.views[3].buf, b.views[4].buf, b.views[5].buf, work, passive, chars, chars + N);
        Py_END_ALLOW_THREADS
        result = PyLong_FromLong(outcome);
    }
    PyMem_Free(work);
    PyMem_Free(passive);
    PyMem_Free(chars);
done:
    release(&b);
    return result;
}

/* ---------------------------------------------------------------- the audit's rows of a scene */

/* check/audit.py::_tangents for the unit normal n (d = 2 or 3): the tangent rows, flattened, in Python's order. */
static void audit_tangents(const double *n, Py_ssize_t d, double *out) {
    if (d == 2) {
        out[0] = n[1], out[1] = -n[0];
        return;
    }
    const double x = n[0], y = n[1], z = n[2], a[3] = {fabs(x), fabs(y), fabs(z)};
    int axis = 0; /* Python's a.index(min(a)): the first smallest */
    if (a[1] < a[axis]) axis = 1;
    if (a[2] < a[axis]) axis = 2;
    double t[3];
    if (axis == 0) t[0] = 0.0, t[1] = z, t[2] = -y;
    else if (axis == 1) t[0] = -z, t[1] = 0.0, t[2] = x;
    else t[0] = y, t[1] = -x, t[2] = 0.0;
    const double norm = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    const double t0 = t[0] / norm, t1 = t[1] / norm, t2 = t[2] / norm;
    out[0] = t0, out[1] = t1, out[2] = t2;
    out[3] = y * t2 - z * t1, out[4] = z * t0 - x * t2, out[5] = x * t1 - y * t0;
}

/* check/audit.py::_mover_velocity of a rigidly moving mover (twist (k,), origin (d,)) at `point`, in Python's order. */
static void audit_mover_velocity(const double *twist, const double *origin, const double *point, Py_ssize_t d, double *out) {
    double r[3];
    for (Py_ssize_t j = 0; j < d; j++) r[j] = point[j] - origin[j];
    if (d == 2) {
        out[0] = twist[0] - twist[2] * r[1], out[1] = twist[1] + twist[2] * r[0];
        return;
    }
    const double wx = twist[3], wy = twist[4], wz = twist[5];
    out[0] = twist[0] + wy * r[2] - wz * r[1];
    out[1] = twist[1] + wz * r[0] - wx * r[2];
    out[2] = twist[2] + wx * r[1] - wy * r[0];
}

/* audit_rows(normals, points, coms, links, twists, origins, driven, through_joints, mu, rows): check/audit.py's
 * contact rows (normal, tangents, arm to the body's com, arm to the other free body's com or zeros, the mover's
 * point velocity or zeros, mu), each number as its Python loop computes it. A contact whose other is a mover
 * (links[i, 1] == -1) moves as its rigid twist and origin, or, where through_joints[i], at its row of driven. */
static PyObject *audit_rows(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    (void)module;
    if (nargs != 10) {
        PyErr_SetString(PyExc_TypeError, "audit_rows(normals, points, coms, links, twists, origins, driven, through_joints, mu, rows) "
                                         "takes 10 arguments");
        return NULL;
    }
    Buffers b = {.taken = 0};
    Py_ssize_t normals[2] = {-1, -1};
    PyObject *result = NULL;
    if (take_next(&b, args[0], "normals", FLOATS, 0, 2, normals) < 0) goto done;
    const Py_ssize_t m = normals[0], d = normals[1], k = d == 2 ? 3 : 6, width = 1 + d * (d + 3);
    if (d != 2 && d != 3) {
        PyErr_SetString(PyExc_ValueError, "normals must be (m, 2) or (m, 3)");
        goto done;
    }
    Py_ssize_t points[2] = {m, d}, coms[2] = {-1, d}, links[2] = {m, 2}, twists[2] = {m, k}, origins[2] = {m, d}, driven[2] = {m, d};
    Py_ssize_t joints[1] = {m}, mu[1] = {m}, rows[2] = {m, width};
    if (take_next(&b, args[1], "points", FLOATS, 0, 2, points) < 0 || take_next(&b, args[2], "coms", FLOATS, 0, 2, coms) < 0 ||
        take_next(&b, args[3], "links", INTEGERS, 0, 2, links) < 0 || take_next(&b, args[4], "twists", FLOATS, 0, 2, twists) < 0 ||
        take_next(&b, args[5], "origins", FLOATS, 0, 2, origins) < 0 || take_next(&b, args[6], "driven", FLOATS, 0, 2, driven) < 0 ||
        take_next(&b, args[7], "through_joints", BOOLEANS, 0, 1, joints) < 0 || take_next(&b, args[8], "mu", FLOATS, 0, 1, mu) < 0 ||
        take_next(&b, args[9], "rows", FLOATS, 1, 2, rows) < 0)
        goto done;
    const double *n = b.views[0].buf, *p = b.views[1].buf, *c = b.views[2].buf, *tw = b.views[4].buf, *o = b.views[5].buf;
    const double *dv = b.views[6].buf, *f = b.views[8].buf;
    const int64_t *l = b.views[3].buf;
    const char *through = b.views[7].buf;
    double *out = b.views[9].buf;
    for (Py_ssize_t i = 0; i < m; i++) {
        if (l[2 * i] < 0 || l[2 * i] >= coms[0] || l[2 * i + 1] < -1 || l[2 * i + 1] >= coms[0]) {
            PyErr_Format(PyExc_ValueError, "contact %zd links body %lld or other %lld outside 0..%zd", i, (long long)l[2 * i],
                         (long long)l[2 * i + 1], coms[0] - 1);
            goto done;
        }
    }
    Py_BEGIN_ALLOW_THREADS
    for (Py_ssize_t i = 0; i < m; i++) {
        const double *point = p + i * d;
        const int64_t body = l[2 * i], other = l[2 * i + 1];
        double *row = out + i * width, *arm_body = row + d * d, *arm_other = arm_body + d, *velocity = arm_other + d;
        for (Py_ssize_t j = 0; j < d; j++) row[j] = n[i * d + j];
        audit_tangents(n + i * d, d, row + d);
        for (Py_ssize_t j = 0; j < d; j++) arm_body[j] = point[j] - c[body * d + j];
        for (Py_ssize_t j = 0; j < d; j++) arm_other[j] = other >= 0 ? point[j] - c[other * d + j] : 0.0;
        if (other >= 0) {
            for (Py_ssize_t j = 0; j < d; j++) velocity[j] = 0.0;
        } else if (through[i]) {
            for (Py_ssize_t j = 0; j < d; j++) velocity[j] = dv[i * d + j];
        } else {
            audit_mover_velocity(tw + i * k, o + i * d, point, d, velocity);
        }
        row[width - 1] = f[i];
    }
    Py_END_ALLOW_THREADS
    result = Py_NewRef(Py_None);
done:
    release(&b);
    return result;
}

static PyMethodDef methods[] = {
    {"audit_laws", (PyCFunction)(void (*)(void))audit_laws, METH_FASTCALL,
     "audit_laws(links, contacts, loads, T, f, facets, directions, facet_scale, slide_speed, sums, u, slips, normal):\n"
     "the audit's per-contact laws, the numba kernel's loops; fills sums (11,), u and slips (m, d), normal (m, 3).\n"
     "See quasistatic.check.audit."},
    {"analyse_frictionless", (PyCFunction)(void (*)(void))analyse_frictionless, METH_FASTCALL,
     "analyse_frictionless(Jn, bn, g, q, forces, zero, motion_rank, force_rank, orthogonal, jacobi_max, slack, support, tight,\n"
     "closed) -> (residual, motion_unique, forces_unique): the frictionless LP pair's analysis, the numba kernel's loops;\n"
     "fills slack (m,) float64 and the three masks (m,) bool. See quasistatic.solvers.lp."},
    {"to_world", (PyCFunction)(void (*)(void))to_world, METH_FASTCALL,
     "to_world(q, c, frames, units, force, T, forces): physical twists and world forces, the numba kernel's loops;\n"
     "fills T (bodies, k) and forces (m, d). See quasistatic.laws.motion.to_world."},
    {"drop_roundoff", (PyCFunction)(void (*)(void))drop_roundoff, METH_FASTCALL,
     "drop_roundoff(values, roundoff): entries of values (rows, c) within roundoff[j] of zero set to 0, in place.\n"
     "See quasistatic.check.motion."},
    {"stack_rows", (PyCFunction)(void (*)(void))stack_rows, METH_FASTCALL,
     "stack_rows(rows, out): copies each row (a 1-D float64 array of out's width) into out (len(rows), width).\n"
     "See quasistatic.laws.assemble."},
    {"assemble_scene", (PyCFunction)(void (*)(void))assemble_scene, METH_FASTCALL,
     "assemble_scene(normals, points, coms, owners, others, twists, origins, places, driven, wrenches, masses, gravity,\n"
     "smallest_length, frames, J, b, g_and_scales): a scene's scales and contact laws, the numpy assembly's arithmetic;\n"
     "fills frames (m, d, d), J (m, d, k bodies; zeros on entry), b (m, d), g_and_scales (k bodies + d + 3,).\n"
     "See quasistatic.laws.assemble."},
    {"nonnegative_fit", (PyCFunction)(void (*)(void))nonnegative_fit, METH_FASTCALL,
     "nonnegative_fit(A, keep, b, x, independent) -> residual: non-negative least squares on the kept columns of A (m, N),\n"
     "the numba kernel's loops; fills x (N,), returns |A x - b|. See quasistatic.solvers.numerics.nnls."},
    {"polygon_vertices", (PyCFunction)(void (*)(void))polygon_vertices, METH_FASTCALL,
     "polygon_vertices(rates, reserve, rows, parallel, skew, slack, vertices) -> count: a polygon's vertices, the numba\n"
     "kernel's loops; fills vertices (pairs, 2), returns their count or -1. See quasistatic.solvers.numerics.polygon."},
    {"closed_rows", (PyCFunction)(void (*)(void))closed_rows, METH_FASTCALL,
     "closed_rows(E, e, by_rank, rank, orthogonal, zero, sigma, basis, inverse, q0, spread) -> (r, residual_square): closed\n"
     "rows factored by Jacobi rotations, the numba kernel's loops; fills sigma (n,), basis (n, n), inverse (n, k), q0 and\n"
     "spread (n,). See quasistatic.solvers.numerics.closed_set."},
    {"row_bounds", (PyCFunction)(void (*)(void))row_bounds, METH_FASTCALL,
     "row_bounds(bank, rhs, inverse, q0, directions, rows, slack, reserve, rates): the listed bank rows' best slack at q0\n"
     "and rates along the directions, the numba kernel's loops; fills reserve (R,) and rates (R, 2) at those rows.\n"
     "See quasistatic.solvers.numerics.closed_set."},
    {"polygon_ball", (PyCFunction)(void (*)(void))polygon_ball, METH_FASTCALL,
     "polygon_ball(q0, directions, vertices, seed, spread, same, distinct, center) -> reach: the ball around a polygon of\n"
     "twists, the numba kernel's loops; fills center (n,), returns its radius, or -1 when every twist is the seed's.\n"
     "See quasistatic.solvers.numerics.polygon."},
    {"fit_or_farkas", (PyCFunction)(void (*)(void))fit_or_farkas, METH_FASTCALL,
     "fit_or_farkas(A, keep, b, margin, ceiling, independent, x, y, bits) -> outcome: the non-negative fit on the columns\n"
     "whose bits keep (int64 words) sets, then its residual's Farkas check, the numba kernel's loops; fills x (N,), y (m,)\n"
     "and bits (words); returns 0 (balances), 1 (excluded) or 2 (neither). See quasistatic.solvers.numerics.nnls."},
    {"audit_rows", (PyCFunction)(void (*)(void))audit_rows, METH_FASTCALL,
     "audit_rows(normals, points, coms, links, twists, origins, driven, through_joints, mu, rows): the audit's contact rows\n"
     "(normal, tangents, arms, mover point velocity, mu), as its Python loop computes them; fills rows (m, 1 + d (d + 3)).\n"
     "See quasistatic.check.audit."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module_definition = {
    PyModuleDef_HEAD_INIT, "quasistatic._kernels", "The audit's laws and the frictionless LP's analysis compiled (no numpy headers): see quasistatic.compiled.",
    -1, methods, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__kernels(void) { return PyModule_Create(&module_definition); }
