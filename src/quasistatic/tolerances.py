"""Every tolerance of the library, named, in one place.

Assembly divides every quantity by the scene's own scales (length, force,
velocity: :class:`quasistatic.model.scales.Scales`), so apart from the input
checks below each tolerance is *scene-relative* and dimensionless: 1e-9 means
"a billionth of the scene's largest load, speed or size", whether the scene is
in millimetres and grams or in metres and kilograms.

Grouped by who uses them: input checks, the audit and the report, the
solvers' linear algebra and LPs, and the exact-cone refinements. A guard
against division by zero (``max(x, 1e-300)``) is not a tolerance and stays
where it is used.
"""

from __future__ import annotations

__all__ = [
    "NORMAL_LENGTH",
    "SMALLEST_LENGTH",
    "AUDIT",
    "MODE_SPEED",
    "ROUNDOFF",
    "DISPLAY_ZERO",
    "TORQUE_LIMIT",
    "ZERO",
    "MOVING",
    "SAME_TWIST",
    "DISTINCT_TWIST",
    "FORCE_RANK",
    "COMPLIANCE_RANK",
    "MOTION_RANK",
    "LP_FEASIBILITY",
    "LINE_RANK",
    "LINE_NULL_SPACE",
    "LINE_PARALLEL_ROW",
    "FORCE_CEILING",
    "FORCE_INTERIOR",
    "PATTERN_NODES",
    "PYRAMID_PATTERN_NODES",
    "ARRANGEMENT_CONTACTS",
    "ARRANGEMENT_ROUNDOFF",
    "BATCH_CONTACTS",
    "BATCH_POINTS",
    "BATCH_TIE",
    "FLOAT_ARRANGEMENT_PLANES",
    "HIGHS_SMALLEST_ENTRY",
    "FARKAS_ROUNDOFF",
    "PIVOT",
    "BASIS_FEASIBILITY",
    "LEMKE_PAIR",
    "FRICTION_ALIGNMENT",
    "FIXED_MODE_RESIDUAL",
    "CONE_ROUNDOFF",
    "FREE_TWIST_DIRECTION",
    "SECTOR_ACTIVE",
    "EXACT_SECTOR_FRICTION",
    "POWER_GAP",
    "RECOVERED_POWER_GAP",
    "POLISHED_RESIDUAL",
    "AT_LOWER_BOUND",
    "JACOBIAN_RANK",
    "NEWTON_STOP",
    "NEWTON_DAMPING",
    "LEAST_SQUARES_STEP",
    "JACOBI_ORTHOGONAL",
    "MODE_BOUNDARY",
    "PLAN_SPEED",
    "PLAN_COST",
    "ROTATION_ORTHONORMAL",
    "QUATERNION_NORM",
    "CONTACT_SEPARATION",
    "PATCH_THICKNESS",
    "DUPLICATE_POINT",
    "CURVED_PATCH_POINTS",
    "MAX_MAGNITUDE",
    "MAX_FRICTION",
    "MAX_PYRAMID_EDGES",
    "MAX_NAME_LENGTH",
    "MAX_DEPTH",
    "MAX_POLYGON_VERTICES",
    "MAX_VALUES",
    "MAX_FILE_BYTES",
    "DETECTION_MARGIN",
    "SIM_LOOKAHEAD",
    "SIM_APPROACH",
    "SIM_PENETRATION",
    "SIM_EVENT_TIME",
    "MAX_DENSE_BYTES",
]

# --------------------------------------------------------------------------- input (physical units)

NORMAL_LENGTH = 1e-3
"""|‖n‖ - 1| a contact normal may have before it is rejected [-]; within it the normal is normalised."""

SMALLEST_LENGTH = 1e-150
"""Smallest length scale [length unit]: its square (in moments) is still a normal float."""

# --------------------------------------------------------------------------- audit and report

AUDIT = 1e-6
"""Default threshold on every residual of the audit (equilibrium, cone, complementarity, dissipation, power) [-]."""

MODE_SPEED = 1e-6
"""Relative speed (per velocity scale) below which a contact is not moving: rolling, not sliding or separating [-]."""

ROUNDOFF = 1e-12
"""Reported twists, forces, velocities and powers below this fraction of the scene's own scale are round-off: shown as 0 [-]."""

DISPLAY_ZERO = 1e-12
"""Entries below this fraction of a column's largest one are printed as 0 (round-off, not data) [-]."""

TORQUE_LIMIT = 1e-6
"""A joint torque exceeds its limit only by more than this fraction of the scene's force scale times the joint's
largest lever arm (the largest Jacobian column entry at its contacts): the forces themselves are audited to
:data:`AUDIT` of the force scale, so a torque exactly at its limit is not called infeasible on round-off [-]."""

# --------------------------------------------------------------------------- solvers: linear algebra and LPs

ZERO = 1e-9
"""A residual, velocity or force below this is zero (a contact is closed, a force carries nothing) [-]."""

MOVING = 10 * ZERO
"""A contact's scene-relative opening or slip speed (or an edge's dissipation rate) above this opens or slides it [-]."""

SAME_TWIST = 1e-7
"""Two twists closer than this (largest entry) are the same motion, and an extreme this close to a point is that point [-]."""

DISTINCT_TWIST = 1e-5
"""The certified search excludes a found twist by a box this wide: the next motion differs by at least this [-]."""

FORCE_RANK = 1e-10
"""Singular values of the closed contacts' normals above this are independent: then the forces are unique [-]."""

COMPLIANCE_RANK = 1e-9
"""Eigenvalues of the compliance on the directions the consistent forces may vary in, above this fraction of its
largest entry, make the least-energy forces unique (a rigid contact's direction has 0; the stiffest spring
a scene may pair with the softest is 1e9 times stiffer) [-]."""

MOTION_RANK = 1e-9
"""Singular values of the loaded contacts' normals above this fix the twist: then the motion is unique [-]."""

LP_FEASIBILITY = 1e-7
"""What HiGHS and SCIP meet constraints to; a certificate or range checked with their output uses the same [-]."""

LINE_RANK = 1e-9
"""Equality rows whose second-smallest singular value (of n) is above this fraction of their largest leave at most
a line of twists: a leaf's extent is then read off in closed form (``numerics/line_extent.py``) [-]."""

LINE_NULL_SPACE = 1e-12
"""... and whose smallest singular value is below this fraction of their largest leave exactly a line [-]."""

LINE_PARALLEL_ROW = 1e-12
"""A row whose rate along a line's unit direction is below this fraction of its norm is parallel to the line [-]."""

KINEMATIC_MULTIPLIERS = 1e10
"""Largest ``|y|_1`` of Farkas multipliers (``y >= 0``, ``Jn^T y = 0``, ``bn.y = 1``) accepted as proof that no twist keeps
every contact closed or opening [-]. Multipliers this large say only that every twist misses some gap row by less than
``1 / |y|_1`` (1e-10) of the scene's velocity, far inside the ``LP_FEASIBILITY`` every certified claim is made to (two
opposed fingers closing at 1e-8 of it already have motions that meet the rows to it: ``ambiguous``, with or without
the bound). Measured: HiGHS returns multipliers of 2e9 for fingers closing at 1e-9 (accepted), 2e11 at 1e-11
(refused), none at 1e-13; the largest on 1,320 random scenes and grasps was 433. The 6-contact bench grasps whose
fingers all follow one twist have five gap planes through one point, missed by 1e-17 in exact arithmetic on the
stored numbers (exact multipliers of 1e16 exist; HiGHS calls the LP infeasible). With the bound, a twist meeting every gap row to within
round-off rules out every accepted certificate without the LP
(:func:`quasistatic.solvers.certify.diagnose.admits_no_multipliers`)."""

FORCE_CEILING = 1e6
"""Largest total scene-relative force a Farkas vector of the mode branch and bound must exclude [-]: its check
``G^T y <= 0`` is met to round-off (1e-16 of the load) only, which rules out every equilibrium with forces below
``LP_FEASIBILITY / round-off``; a million times the scene's force scale is past what SCIP itself resolves, whose
equilibrium rows are met to ``LP_FEASIBILITY`` (at 1e6 that is a tenth of the load)."""

FORCE_INTERIOR = 1e-3
"""Least value, relative to the load's largest scene-relative entry, that a point of a motion's consistent force
set is asked to give every column not forced to zero, when one is sought by NNLS to decide whether the normal
forces vary (:mod:`quasistatic.solvers.numerics.forces`) [-]. Not a tolerance on any law: a point this far inside
lets steps along the set's directions move a normal force by more than ``LP_FEASIBILITY``; where NNLS finds none
(a column the set holds near zero), one LP decides, as it always did."""

PATTERN_NODES = 512
"""Most nodes of the planar mode branch and bound (:mod:`quasistatic.solvers.certify.patterns`) before it gives
the proof to the SCIP search [-]: measured, the benchmark's 2-D grasps of 2-8 contacts need 6-300 (their ambiguous
ones listed in 12-130) and 840 random scenes at most 124, all decided; a node costs ~55 us, so the budget wastes at
most ~30 ms before SCIP."""

PYRAMID_PATTERN_NODES = 8192
"""Most nodes of the 3-D pyramid's mode branch and bound (:mod:`quasistatic.solvers.certify.patterns`) before it
gives the proof to the SCIP search [-]: measured on the 8-edge pyramid, the benchmark's 3-D grasps of 4-8 contacts
need 203-4023 (0.02-0.3 s; 208-4822 before the slip's four arcs and a proof's least loaded contacts first), where SCIP
took 0.2-30 s; of 240 random scenes of 2-4 contacts, 235 were decided
within it. A node costs 55-90 us (about 64 on those grasps), so the budget wastes at most about 0.6 s before SCIP.
The same budget bounds the search of the exact cones' sector relaxation (``patterns.relaxation_excluded``)."""

ARRANGEMENT_CONTACTS = 16
"""Most contacts of a planar one-body problem the vertex certificate (:mod:`quasistatic.solvers.certify.arrangement`)
is tried on [-]: it solves every triple of the up to ``2 m`` twist planes, C(32, 3) = 4960 3x3 systems at 16 contacts
(a few milliseconds); past it the mode branch and bound decides alone."""

ARRANGEMENT_ROUNDOFF = 1e-12
"""Relative round-off of the vertex certificate's 3x3 solves [-]: three twist-plane normals whose determinant is below
this fraction of the longest normal's cube are dependent (they meet in a line, or not at all; scene-relative normals
have lengths 1 to 2), a ray's rate along a plane below it is zero, and a computed vertex meets its planes to this
fraction of ``|n| |w|_1 + |r|``. A zero rate or a near plane only adds force generators (it can keep a vertex from
being excluded, never exclude one); dependent normals are the one round-off assumption, as for the branch and bound's
parallel lines: computed to 1e-16, normals this close to dependent meet 1e12 times farther than their offsets."""

BATCH_CONTACTS = 8
"""Most contacts of a sweep's planar points decided together (:mod:`quasistatic.solvers.certify.batched`) [-]: the
vertex certificate's arrays hold every triple of the up to ``2 m`` twist planes against every plane, per point
(C(16, 3) x 16 x 3 numbers, 215 KB a point at 8 contacts; 3.8 MB at the 16 of ``ARRANGEMENT_CONTACTS``); past it
each point is solved alone."""

BATCH_POINTS = 256
"""Most points decided in one stack [-]: a sweep's chunks hold at most 256 by default, and a larger chunk
(``chunk_size``) is decided 256 points at a time, so the arrays above stay below about 60 MB."""

BATCH_TIE = 2.0
"""A batched test's value within this factor of its threshold, either side, leaves the point to the per-point solve
(:mod:`quasistatic.solvers.certify.batched`) [-]: the batch sums the same products in another order, so the two can
differ in the last bits; far from the threshold they fall on the same side. A factor, not a margin in the laws: the
point is then only solved alone, as before."""

FLOAT_ARRANGEMENT_PLANES = 6
"""Most twist planes (gap rows plus slip rows) on which the vertex certificate's claim "the seed is the only motion" is
first tried in Python floats (:mod:`quasistatic.solvers.certify.arrangement_floats`) [-]: up to C(6, 3) = 20 triples
the scalar loops beat the whole-array code's fixed cost of about a hundred numpy calls; past it the arrays are cheaper.
Not a tolerance: the same claim, the same margins, either way."""

HIGHS_SMALLEST_ENTRY = 1e-12
"""HiGHS drops matrix entries below this (its smallest allowed): a 1e-10 tilt is data, not noise [-]."""

FARKAS_ROUNDOFF = 1e-12
"""An LP's infeasibility checked on a Farkas vector ``y`` (HiGHS's dual ray, or a non-negative fit's): entries of
``y`` (of ``A^T y``) below this fraction of its largest (of their own scale, ``|A|^T |y|``) are round-off, taken as
zero; the bound the vector proves must exceed this fraction of its terms (measured: HiGHS's rays on 283
infeasible leaves of the bench grasps pass by 9e-4 of them or more) [-]."""

PIVOT = 1e-11
"""Lemke's pivot tolerance and tie width, relative to the entering column's largest entry [-]."""

BASIS_FEASIBILITY = 1e-10
"""Slack allowed when a complementary basis is reused after the pyramid's edges turned [-]."""

LEMKE_PAIR = 1e-10
"""Largest violation of the frictionless LP's optimality conditions a Lemke pair may have before HiGHS decides [-]."""

# --------------------------------------------------------------------------- exact 3-D cones

FRICTION_ALIGNMENT = 1e-9
"""Distance of a sliding contact's friction from ``-mu cn slip/|slip|`` accepted as exact maximum dissipation [-]."""

FIXED_MODE_RESIDUAL = 1e-10
"""Largest residual of the fixed-mode exact laws (equilibrium, closed, rolling) at which Newton's method has converged [-]."""

CONE_ROUNDOFF = 1e-12
"""Round-off allowed on a force that must lie inside its exact cone, or have a non-negative normal part [-]."""

FREE_TWIST_DIRECTION = 1e-6
"""A null vector of the fixed-mode laws' Jacobian whose twist part exceeds this leaves the motion free (a continuum) [-]."""

SECTOR_ACTIVE = 1e-9
"""Size above which a part of the sector relaxation's convex hull is the one in use [-]."""

EXACT_SECTOR_FRICTION = 1e-6
"""A relaxed point whose friction is this close to the exact law's needs no finer sectors [-]."""

POWER_GAP = 1e-8
"""Power gap P_zc - P_c of the paper's program below which eq. 19 holds with equality: a motion [-]."""

RECOVERED_POWER_GAP = 1e-7
"""Power gap accepted when the paper's forces are recovered at a fixed twist (the twist carries SCIP's 1e-7) [-]."""

POLISHED_RESIDUAL = 1e-12
"""Largest residual of the fixed-mode laws at which the paper's SCIP point counts as polished [-]."""

# --------------------------------------------------------------------------- numerical methods (stopping rules, not physics)

AT_LOWER_BOUND = 1e-12
"""An LP variable within this of its lower bound is at it (a range's minimum is then known without an LP) [-]."""

JACOBIAN_RANK = 1e-8
"""Singular values of the fixed-mode laws' Jacobian below this fraction of the largest are zero [-]."""

NEWTON_STOP = 1e-14
"""The fast path's Newton iteration stops once the fixed-mode residual is below this [-]."""

NEWTON_DAMPING = 1e-12
"""Relative Levenberg damping of the fast path's Newton steps: only matters where the Jacobian is singular [-]."""

LEAST_SQUARES_STEP = 1e-15
"""scipy's least-squares stops on steps, cost changes or gradients below this: iterate to machine precision [-]."""

JACOBI_ORTHOGONAL = 1e-15
"""Two columns of a one-sided Jacobi SVD are orthogonal when their cosine is below this (working precision) [-]."""

# --------------------------------------------------------------------------- sensitivities and planning

MODE_BOUNDARY = 1e-6
"""A quantity that decides a contact's mode (normal speed, slip speed, normal force, distance of a rolling
contact's force from its cone) below this, scene-relative, puts the motion on a mode boundary: the one-sided
derivatives differ there, so no derivative is given. The same size as :data:`MODE_SPEED` and :data:`AUDIT`,
to which the reported motion itself is known [-]."""

PLAN_SPEED = 1e-2
"""Default smallest speed the planner gives a sliding contact's slip and a separating contact's normal velocity,
relative to the wanted motion's speed at the scene's length scale [-]: well above :data:`MODE_SPEED` (1e-6), so
the audit names the planned mode, and small enough not to cost a visible part of the inputs."""

PLAN_COST = 1e-12
"""The 3-D planner's NLP (SLSQP) stops when its cost changes by less than this fraction of its starting cost [-]:
on Brock's controlled slip it converges in 2 iterations; an absolute 1e-15 on its cost of 2e-5 ran all 500 (round-off)."""

# --------------------------------------------------------------------------- geometry and contact detection (adapters/)

ROTATION_ORTHONORMAL = 1e-6
"""Largest entry of |R^T R - I| a pose's rotation matrix may have [-]; within it R is projected onto the nearest
rotation. URDF and mesh files print 6 to 9 digits: their matrices are orthonormal to about 1e-7.
"""

QUATERNION_NORM = 1e-3
"""|‖q‖ - 1| a pose's quaternion may have before it is rejected [-]; within it q is normalised (as for normals)."""

CONTACT_SEPARATION = 1e-3
"""How far apart contact detection moves two touching or overlapping shapes before it computes their contact
patch, relative to the smaller one's extent [-]. coal finds the normal of overlapping polytopes with EPA, off by
about 1e-6 rad (2.5e-6 measured for a box resting on a box), and that of separate ones with GJK, to round-off
(1e-13): detection separates them, reads the patch, and moves the first shape's points back.
"""

PATCH_THICKNESS = 1e-6
"""Thickness of a contact patch beyond the margin, relative to the smaller shape's extent [-]: a vertex this
close to the margin still belongs to the patch (round-off of the normal times the shape's size).
"""

DUPLICATE_POINT = 1e-6
"""Two contact points of one pair closer than this, relative to the smaller shape's extent, are one point; a
point this close to the segment between its neighbours is on an edge, not a vertex, of the contact polygon;
a line along the normal through a patch corner that misses a shape by less than this still meets it [-].
"""

GRAZING_FACE = 1e-3
"""A face of a shape whose normal is within this of perpendicular to a contact's normal (their cosine) runs along
the line through a patch corner, rather than crossing it [-]. The corner lies on that face's edge only to coal's
round-off (7e-11 of a 0.25 box, measured), which a crossing divides by the cosine: a box tilted 1e-5 rad on a block
had its corners' gaps off by 7e-6 (3e-5 of its size, swapped between corners). At 1e-3 round-off moves a gap by
1e-7 of the size, below :data:`DUPLICATE_POINT`, and a face this steep spans a thousandth of the shape across.
Such a face still bounds the line once moved out by the contact slack (``adapters/detect._in_planes``): an
overhanging one then stops it within the slack of the face.
"""

CURVED_PATCH_POINTS = 8
"""Vertices of the regular polygon inscribed in a curved flat contact (a cylinder standing on its end face) [-].
An inscribed polygon keeps the support region inside the true disc, so a stability verdict stays on the
safe side; its area is 90 % of the disc's at 8 vertices.
"""

DETECTION_MARGIN = 1e-4
"""Default contact margin, relative to the largest free body's bounding radius [-]: gaps up to it count
as contacts. Geometry from CAD or forward kinematics is exact to far better than this, so a part resting
on another is found touching, while parts a ten-thousandth of their size apart (a 0.01 mm gap on a 10 cm
part) are not: a user who wants a looser test gives ``contact_detection.margin`` in length units.
"""

# --------------------------------------------------------------------------- simulation (sim/)

SIM_LOOKAHEAD = 0.05
"""Width of the band around each body in which a simulation tracks surfaces not yet touching, relative to
the largest free body's size [-]. A step is shortened so that no point moves farther than the band, and so
that no tracked surface closes its gap within the step: a thin part cannot be passed through in one step.
"""

SIM_APPROACH = 0.5
"""A surface closing in is stopped at this fraction of the contact margin [-]: inside the margin, so it is
a contact at the next step, with room left for the step's second-order error (a step moves along the
tangent of a curved path).
"""

SIM_PENETRATION = 0.5
"""Penetration corrected at the start of a step, as a fraction of the contact margin [-]. A step follows
the exact screw of its twist, but a contact point that slides over a rotating face drifts by the square of
the step; the bodies are then moved out along the contact normals by the least motion that closes it, so
penetration never accumulates. The largest depth before correction is recorded at every step.
"""

SIM_EVENT_TIME = 1.0 / 64.0
"""Default time tolerance of an event (a contact made or broken, a mode or status change), as a fraction
of the time step [-]: the step where it happens is bisected until the event lies in a window this wide.
"""

SIM_POWER_TIE = 1e-9
"""Input powers of an ambiguous answer's motions that differ by less than this, relative to the largest power
of any listed motion, tie for the least (``ambiguous="min_power"``) [-]: the choice among them is then not the rule's, and the
run records which motions tied.
"""

# --------------------------------------------------------------------------- input limits (what a scene may hold at all)

MAX_MAGNITUDE = 1e30
"""Largest |x| of any number in a scene [any unit]: the numerics' range, whatever the units.

Assembly multiplies inputs before it scales them: a force is mass x gravity, a moment force x length, a
power force x velocity (itself twist x length), and a norm squares each of these. Up to eight factors of
1e30 stay finite (1e240 < 1e308). Measured on the examples: every input x 1e75 still gives the same
answer; x 1e100 overflows the force scale's norm (NaN in the audit and Infinity in the JSON). 1e30 is
also beyond what a manipulated object holds in any unit system (the Earth's mass is 6e27 g).
"""

MAX_FRICTION = 1e3
"""Largest friction coefficient mu [-]. Measured coefficients stay below 10, and mu = 1e3 already grips
like infinite friction. SCIP meets constraints to 1e-7 of the scene's forces, which friction multiplies
by mu: on the examples mu = 1e4 still solves cleanly, mu = 1e5 gives SCIP "unresolved numerical
troubles" (ERROR lines on stderr, a 25 s search) and mu = 1e308 an exception while the model is built.
"""

MAX_PYRAMID_EDGES = 64
"""Most edges K of a ``pyramid:K`` friction model: its largest error is 1 - cos(pi/K) = 0.12 % of the
cone at K = 64 (use ``exact`` for better); measured, the five-contact puck takes 40 s at K = 32 and runs
out of the 60 s search at K = 64, and K = 1e8 would allocate gigabytes before the search starts.
"""

MAX_NAME_LENGTH = 256
"""Most characters in a body, mover or robot name: names are printed in tables and error messages,
and compared for "did you mean" hints, whose cost grows with their length.
"""

MAX_DEPTH = 64
"""Most levels of nested lists and mappings in a scene: the format needs 5 (the scene, its contacts, a
contact, its jacobian, a row); deeper input is rejected before anything recursive walks it.
"""

MAX_POLYGON_VERTICES = 1024
"""Most vertices of one planar polygon: polygon-polygon detection compares every vertex of one with every face
of the other, (n, m) arrays per pair and step (1024 x 1024: 8 MiB). A convex polygon cannot hold many more
corners anyway: a regular 4,400-gon's corners lie within :data:`DUPLICATE_POINT` of its edges (a disk is a ``disk``).
"""

MAX_VALUES = 1_000_000
"""Most values (numbers, strings, lists, mappings) a scene may hold once YAML aliases are expanded: a
10,000-contact scene holds about 150,000; a few hundred bytes of nested aliases ("billion laughs")
would otherwise expand to billions.
"""

MAX_FILE_BYTES = 16 * 1024 * 1024
"""Largest scene file read [bytes]: about 100 times a 10,000-contact scene. Reading stops one byte past it,
whatever the file claims to hold (``/dev/zero`` has no end).
"""

MAX_DENSE_BYTES = 2**30
"""Largest dense matrix a frictional method may build [bytes]: the polyhedral laws' complementarity matrix
grows as the square of the contacts (a 3-D box on 10,000 frictional points: 12 GiB, 1,000 points: 0.8 GiB).
Past it the method is not run and the answer is an honest ``failed`` (:mod:`quasistatic.solvers.oversize`).
"""
