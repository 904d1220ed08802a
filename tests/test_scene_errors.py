"""Bad scene input: every kind is a SceneError naming the field path and the offending value.

Also a hypothesis property: random mutations of a valid scene dict never make
``load_scene`` or ``solve(method="lp")`` raise anything but the library's own exceptions.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

import quasistatic as qs


def scene_2d() -> dict[str, Any]:
    """A valid 2-D scene: a box on a table, a fixed finger and a robot-driven hand."""
    return {
        "quasistatic": 1,
        "dimension": 2,
        "gravity": [0.0, -9.81],
        "friction": "none",
        "bodies": {"box": {"mass": 2.0, "com": [0.2, 0.1], "wrench": [0.0, 0.0, 0.0]}},
        "movers": {
            "table": None,
            "finger": {"twist": [0.0, 0.0, 0.0], "origin": [0.0, 0.0]},
            "hand": {"robot": "arm"},
        },
        "robots": {"arm": {"joint_velocities": [0.1]}},
        "contacts": [
            {"body": "box", "other": "table", "point": [0.0, 0.0], "normal": [0.0, 1.0], "mu": 0.0},
            {"body": "box", "other": "table", "point": [0.4, 0.0], "normal": [0.0, 1.0]},
            {"body": "box", "other": "finger", "point": [0.0, 0.1], "normal": [1.0, 0.0]},
            {"body": "box", "other": "hand", "point": [0.4, 0.1], "normal": [-1.0, 0.0], "jacobian": [[-1.0], [0.0]]},
        ],
    }


def scene_3d() -> dict[str, Any]:
    """A valid 3-D scene: a box on three floor points against two walls (3-2-1 fixture), some friction."""
    return {
        "quasistatic": 1,
        "dimension": 3,
        "gravity": [-2.0, -1.5, -9.81],
        "friction": "exact",
        "bodies": {"box": {"mass": 1.5, "com": [0.2, 0.15, 0.1], "wrench": [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]}},
        "movers": {"floor": {}, "ywall": {"twist": [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]}, "pusher": {"robot": "arm"}},
        "robots": {"arm": {"joint_velocities": [0.05, -0.02]}},
        "contacts": [
            {"body": "box", "other": "floor", "point": [0.05, 0.05, 0.0], "normal": [0.0, 0.0, 1.0]},
            {"body": "box", "other": "floor", "point": [0.35, 0.05, 0.0], "normal": [0.0, 0.0, 1.0], "mu": 0.3},
            {"body": "box", "other": "floor", "point": [0.2, 0.25, 0.0], "normal": [0.0, 0.0, 1.0]},
            {
                "body": "box",
                "other": "pusher",
                "point": [0.0, 0.05, 0.1],
                "normal": [1.0, 0.0, 0.0],
                "jacobian": [[1.0, 0.0], [0.0, 0.0], [0.0, 0.5]],
            },
            {
                "body": "box",
                "other": "pusher",
                "point": [0.0, 0.25, 0.1],
                "normal": [1.0, 0.0, 0.0],
                "jacobian": [[1.0, 0.0], [0.0, 0.0], [0.0, 0.5]],
            },
            {"body": "box", "other": "ywall", "point": [0.2, 0.0, 0.1], "normal": [0.0, 1.0, 0.0]},
        ],
    }


def raises_scene_error(data: dict[str, Any], field: str, *fragments: str) -> qs.SceneError:
    """Load ``data``, expect a SceneError at ``field`` whose message holds every fragment."""
    with pytest.raises(qs.SceneError) as info:
        qs.load_scene(data)
    err = info.value
    assert err.field == field, str(err)
    message = str(err)
    assert message.startswith(f"{field}: "), message
    for fragment in fragments:
        assert fragment in message, message
    return err


def test_valid_scenes_load() -> None:
    assert isinstance(qs.load_scene(scene_2d()), qs.Scene)
    assert isinstance(qs.load_scene(scene_3d()), qs.Scene)


# --------------------------------------------------------------------------- keys


def test_unknown_optional_top_level_key_suggests_the_right_one() -> None:
    data = scene_2d()
    data["gravty"] = data.pop("gravity")
    err = raises_scene_error(data, "gravty", "unknown key", "did you mean 'gravity'?", "'gravty'")
    assert err.value == "gravty"


@pytest.mark.parametrize(
    ("mutate", "field", "suggestion"),
    [
        (lambda d: d["bodies"]["box"].__setitem__("wrnch", d["bodies"]["box"].pop("wrench")), "bodies.box.wrnch", "wrench"),
        (lambda d: d["movers"]["finger"].__setitem__("twst", d["movers"]["finger"].pop("twist")), "movers.finger.twst", "twist"),
        (lambda d: d["contacts"][3].__setitem__("jacobain", [[-1.0], [0.0]]), "contacts[3].jacobain", "jacobian"),
        (lambda d: d["contacts"][0].__setitem__("mue", d["contacts"][0].pop("mu")), "contacts[0].mue", "mu"),
    ],
    ids=["body-wrench", "mover-twist", "contact-jacobian", "contact-mu"],
)
def test_unknown_optional_nested_key_suggests_the_right_one(mutate: Callable[[dict[str, Any]], None], field: str, suggestion: str) -> None:
    data = scene_2d()
    mutate(data)
    key = field.rsplit(".", 1)[1]
    raises_scene_error(data, field, "unknown key", f"did you mean {suggestion!r}?", repr(key))


def test_typo_of_required_top_level_key_suggests_the_right_one() -> None:
    data = scene_2d()
    data["contcts"] = data.pop("contacts")
    raises_scene_error(data, "contcts", "unknown key", "did you mean 'contacts'?", "'contcts'")


def test_typo_of_required_contact_key_suggests_the_right_one() -> None:
    data = scene_2d()
    data["contacts"][1]["nromal"] = data["contacts"][1].pop("normal")
    raises_scene_error(data, "contacts[1].nromal", "unknown key", "did you mean 'normal'?", "'nromal'")


def test_typo_of_required_key_is_at_least_reported_as_missing() -> None:
    """Whatever the wording, the error names the key that the typo left out."""
    data = scene_2d()
    data["contacts"][1]["nromal"] = data["contacts"][1].pop("normal")
    with pytest.raises(qs.SceneError) as info:
        qs.load_scene(data)
    assert "contacts[1]" in info.value.field


@pytest.mark.parametrize(
    ("path", "field"),
    [
        (("bodies",), "bodies"),
        (("contacts",), "contacts"),
        (("quasistatic",), "quasistatic"),
        (("bodies", "box", "mass"), "bodies.box.mass"),
        (("bodies", "box", "com"), "bodies.box.com"),
        (("contacts", 2, "point"), "contacts[2].point"),
        (("contacts", 2, "normal"), "contacts[2].normal"),
        (("contacts", 2, "body"), "contacts[2].body"),
        (("contacts", 2, "other"), "contacts[2].other"),
        (("robots", "arm", "joint_velocities"), "robots.arm.joint_velocities"),
    ],
)
def test_missing_required_key(path: tuple[Any, ...], field: str) -> None:
    data = scene_2d()
    parent: Any = data
    for part in path[:-1]:
        parent = parent[part]
    del parent[path[-1]]
    err = raises_scene_error(data, field, "required key is missing")
    assert "got" not in str(err)  # nothing was given, so no value is shown


@pytest.mark.parametrize("version", [2, 0, "1", "v1"])
def test_wrong_format_version(version: Any) -> None:
    data = scene_2d()
    data["quasistatic"] = version
    err = raises_scene_error(data, "quasistatic", "unsupported format version", f"(got {version!r})")
    assert err.value == version


def test_not_a_mapping() -> None:
    with pytest.raises(qs.SceneError) as info:
        qs.load_scene([1, 2, 3])  # type: ignore[arg-type]
    assert "mapping" in str(info.value)


# --------------------------------------------------------------------------- vectors


@pytest.mark.parametrize(
    ("dimension", "path", "field", "bad"),
    [
        (2, ("bodies", "box", "com"), "bodies.box.com", [0.2, 0.1, 0.0]),
        (2, ("contacts", 1, "point"), "contacts[1].point", [0.4]),
        (2, ("contacts", 1, "normal"), "contacts[1].normal", [0.0, 1.0, 0.0]),
        (2, ("gravity",), "gravity", [0.0, 0.0, -9.81]),
        (2, ("bodies", "box", "wrench"), "bodies.box.wrench", [0.0, 0.0]),
        (2, ("movers", "finger", "twist"), "movers.finger.twist", [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
        (2, ("movers", "finger", "origin"), "movers.finger.origin", [0.0, 0.0, 0.0]),
        (3, ("bodies", "box", "com"), "bodies.box.com", [0.2, 0.15]),
        (3, ("contacts", 0, "point"), "contacts[0].point", [0.05, 0.05]),
        (3, ("contacts", 0, "normal"), "contacts[0].normal", [0.0, 1.0]),
        (3, ("gravity",), "gravity", [0.0, -9.81]),
        (3, ("bodies", "box", "wrench"), "bodies.box.wrench", [0.0, 0.0, 0.0]),
        (3, ("movers", "ywall", "twist"), "movers.ywall.twist", [0.0, 0.0, 0.0]),
    ],
)
def test_wrong_vector_length(dimension: int, path: tuple[Any, ...], field: str, bad: list[float]) -> None:
    data = scene_2d() if dimension == 2 else scene_3d()
    parent: Any = data
    for part in path[:-1]:
        parent = parent[part]
    parent[path[-1]] = bad
    twist_size = 3 if dimension == 2 else 6
    expected = twist_size if field.endswith(("wrench", "twist")) else dimension
    err = raises_scene_error(data, field, f"expected a list of {expected} numbers", repr(bad))
    assert list(err.value) == bad


def test_zero_normal() -> None:
    data = scene_2d()
    data["contacts"][1]["normal"] = [0.0, 0.0]
    raises_scene_error(data, "contacts[1].normal", "unit vector", "[0.0, 0.0]")


@pytest.mark.parametrize("bad", [[math.nan, 1.0], [0.0, math.inf]])
def test_non_finite_normal(bad: list[float]) -> None:
    data = scene_2d()
    data["contacts"][1]["normal"] = bad
    raises_scene_error(data, "contacts[1].normal", "finite", repr(bad))


@pytest.mark.parametrize("bad", [[0.0, 1.1], [0.0, 0.998], [0.66, 0.88]])
def test_non_unit_normal(bad: list[float]) -> None:
    data = scene_2d()
    data["contacts"][1]["normal"] = bad
    length = math.hypot(*bad)
    raises_scene_error(data, "contacts[1].normal", "unit vector", f"{length:.6g}", repr(bad))


@pytest.mark.parametrize("given", [[0.0, 1.0005], [0.0, 0.9992], [0.6, 0.8006], [-0.3, 0.9545]])
def test_nearly_unit_normal_is_normalised(given: list[float]) -> None:
    """Within 1e-3 of unit length the normal is accepted and divided by its length."""
    data = scene_2d()
    data["contacts"][1]["normal"] = given
    normal = np.asarray(qs.load_scene(data).contacts[1].normal)
    assert np.linalg.norm(normal) == pytest.approx(1.0, abs=1e-15)
    np.testing.assert_allclose(normal, np.asarray(given) / np.linalg.norm(given), rtol=0, atol=1e-15)


def test_nearly_unit_normal_is_normalised_3d() -> None:
    data = scene_3d()
    data["contacts"][5]["normal"] = [0.0, 1.0007, 0.0]
    assert np.asarray(qs.load_scene(data).contacts[5].normal) == pytest.approx([0.0, 1.0, 0.0], abs=1e-15)


# --------------------------------------------------------------------------- numbers


def test_negative_mu() -> None:
    data = scene_2d()
    data["contacts"][1]["mu"] = -0.2
    err = raises_scene_error(data, "contacts[1].mu", ">= 0", "-0.2")
    assert err.value == -0.2


def test_negative_mass() -> None:
    data = scene_2d()
    data["bodies"]["box"]["mass"] = -1.5
    err = raises_scene_error(data, "bodies.box.mass", ">= 0", "-1.5")
    assert err.value == -1.5


@pytest.mark.parametrize("bad", [math.nan, math.inf, "heavy", None, [1.0]])
def test_mass_not_a_finite_number(bad: Any) -> None:
    data = scene_2d()
    data["bodies"]["box"]["mass"] = bad
    raises_scene_error(data, "bodies.box.mass", repr(bad))


@pytest.mark.parametrize("bad", [math.nan, -math.inf])
def test_non_finite_mu(bad: float) -> None:
    data = scene_2d()
    data["contacts"][0]["mu"] = bad
    raises_scene_error(data, "contacts[0].mu", "finite", repr(bad))


@pytest.mark.parametrize(
    ("field", "mutate"),
    [
        ("bodies.box.mass", lambda d: d["bodies"]["box"].__setitem__("mass", True)),
        ("contacts[0].mu", lambda d: d["contacts"][0].__setitem__("mu", True)),
        ("bodies.box.mass", lambda d: d["bodies"]["box"].__setitem__("mass", "2.0")),
        ("robots.arm.joint_velocities[0]", lambda d: d["robots"]["arm"].__setitem__("joint_velocities", [True])),
        ("robots.arm.joint_velocities[0]", lambda d: d["robots"]["arm"].__setitem__("joint_velocities", ["0.1"])),
    ],
    ids=["mass-bool", "mu-bool", "mass-str", "joint-bool", "joint-str"],
)
def test_booleans_and_strings_are_not_numbers(field: str, mutate: Callable[[dict[str, Any]], None]) -> None:
    data = scene_2d()
    mutate(data)
    with pytest.raises(qs.SceneError) as info:
        qs.load_scene(data)
    assert info.value.field.startswith(field)


# --------------------------------------------------------------------------- names


def test_contact_naming_an_unknown_body() -> None:
    data = scene_2d()
    data["contacts"][2]["body"] = "bx"
    err = raises_scene_error(data, "contacts[2].body", "no free body of that name", "did you mean 'box'?", "'bx'")
    assert err.value == "bx"


def test_contact_naming_an_unknown_body_far_from_any_name() -> None:
    data = scene_2d()
    data["contacts"][2]["body"] = "zzzzzz"
    raises_scene_error(data, "contacts[2].body", "no free body of that name", "known: 'box'", "'zzzzzz'")


def test_contact_body_that_is_a_mover() -> None:
    data = scene_2d()
    data["contacts"][0]["body"] = "finger"
    data["contacts"][0]["other"] = "table"
    raises_scene_error(data, "contacts[0].body", "must be a free body", "is a mover", "'finger'")


def test_contact_other_unknown() -> None:
    data = scene_2d()
    data["contacts"][0]["other"] = "tabel"
    raises_scene_error(data, "contacts[0].other", "no body or mover of that name", "did you mean 'table'?", "'tabel'")


def test_contact_body_touching_itself() -> None:
    data = scene_2d()
    data["contacts"][0]["other"] = "box"
    raises_scene_error(data, "contacts[0].other", "cannot touch itself", "'box'")


def test_name_used_for_a_body_and_a_mover() -> None:
    data = scene_2d()
    data["movers"]["box"] = None
    raises_scene_error(data, "movers.box", "name already used", "'box'")


def test_mover_naming_an_unknown_robot() -> None:
    data = scene_2d()
    data["movers"]["hand"]["robot"] = "amr"
    raises_scene_error(data, "movers.hand.robot", "no robot of that name", "did you mean 'arm'?", "'amr'")


def test_robot_driven_mover_with_a_twist() -> None:
    data = scene_2d()
    data["movers"]["hand"]["twist"] = [0.0, 0.0, 0.0]
    raises_scene_error(data, "movers.hand.twist", "give no twist", "[0.0, 0.0, 0.0]")


# --------------------------------------------------------------------------- robots


def test_robot_contact_without_jacobian() -> None:
    data = scene_2d()
    del data["contacts"][3]["jacobian"]
    raises_scene_error(data, "contacts[3].jacobian", "required", "'hand'", "'arm'", "2 x 1")


@pytest.mark.parametrize("bad", [[[-1.0, 0.0]], [[-1.0], [0.0], [0.0]], [[-1.0, 0.0], [0.0, 0.0]]])
def test_jacobian_of_wrong_shape(bad: list[list[float]]) -> None:
    data = scene_2d()
    data["contacts"][3]["jacobian"] = bad
    shape = np.array(bad).shape
    raises_scene_error(data, "contacts[3].jacobian", "expected shape (2, 1)", str(shape))


def test_jacobian_of_wrong_shape_3d() -> None:
    data = scene_3d()
    data["contacts"][3]["jacobian"] = [[1.0, 0.0], [0.0, 0.0]]
    raises_scene_error(data, "contacts[3].jacobian", "expected shape (3, 2)", "(2, 2)")


def test_ragged_jacobian() -> None:
    data = scene_3d()
    data["contacts"][3]["jacobian"] = [[1.0, 0.0], [0.0], [0.0, 0.5]]
    with pytest.raises(qs.SceneError) as info:
        qs.load_scene(data)
    assert info.value.field == "contacts[3].jacobian"


def test_non_finite_jacobian() -> None:
    data = scene_2d()
    data["contacts"][3]["jacobian"] = [[math.nan], [0.0]]
    raises_scene_error(data, "contacts[3].jacobian", "finite", "nan")


def test_jacobian_on_a_contact_with_a_non_robot_mover() -> None:
    data = scene_2d()
    data["contacts"][0]["jacobian"] = [[0.0], [1.0]]
    raises_scene_error(data, "contacts[0].jacobian", "only contacts with a robot-driven mover", "'table'")


def test_jacobian_on_a_contact_with_a_non_robot_mover_shows_the_value() -> None:
    data = scene_2d()
    data["contacts"][0]["jacobian"] = [[0.0], [1.0]]
    raises_scene_error(data, "contacts[0].jacobian", "[[0.0], [1.0]]")


@pytest.mark.parametrize(
    ("bad", "field"),
    [
        (["fast"], "robots.arm.joint_velocities[0]"),
        ([None], "robots.arm.joint_velocities[0]"),
        ([[0.1, 0.2]], "robots.arm.joint_velocities[0]"),
        (0.1, "robots.arm.joint_velocities"),
        ("0.1", "robots.arm.joint_velocities"),
        ({"j1": 0.1}, "robots.arm.joint_velocities"),
    ],
)
def test_joint_velocities_not_numbers(bad: Any, field: str) -> None:
    data = scene_2d()
    data["robots"]["arm"]["joint_velocities"] = bad
    shown = bad[0] if field.endswith("[0]") else bad
    raises_scene_error(data, field, repr(shown))


def test_non_finite_joint_velocity() -> None:
    data = scene_2d()
    data["robots"]["arm"]["joint_velocities"] = [math.inf]
    raises_scene_error(data, "robots.arm.joint_velocities", "finite", "inf")


# --------------------------------------------------------------------------- scene-wide


@pytest.mark.parametrize("bad", [1, 4, "3"])
def test_bad_dimension(bad: Any) -> None:
    data = scene_2d()
    data["dimension"] = bad
    raises_scene_error(data, "dimension", repr(bad))


@pytest.mark.parametrize("bad", ["fuzzy", "pyramid:2", "pyramid:x"])
def test_bad_friction_model(bad: str) -> None:
    data = scene_3d()
    data["friction"] = bad
    raises_scene_error(data, "friction", repr(bad))


def test_pyramid_in_2d() -> None:
    data = scene_2d()
    data["friction"] = "pyramid:4"
    raises_scene_error(data, "friction", "3-D", "'pyramid:4'")


def test_no_free_body() -> None:
    data = scene_2d()
    data["bodies"] = {}
    data["contacts"] = []
    raises_scene_error(data, "bodies", "at least one free body")


# --------------------------------------------------------------------------- property: never another exception

_SPECIAL_FLOATS = st.sampled_from([math.nan, math.inf, -math.inf, 1e308, -1e308, 1e-308, 0.0, -0.0, -1.0, 1e12])
_NUMBERS = st.one_of(
    st.floats(min_value=-10.0, max_value=10.0),
    st.floats(min_value=-10.0, max_value=10.0),
    st.integers(min_value=-3, max_value=3),
    _SPECIAL_FLOATS,
    st.floats(allow_nan=True, allow_infinity=True),
)
_LEAVES = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(10**30), max_value=10**30),
    st.sampled_from([10**400, -(10**400), 2, 3, 6, 1]),
    st.floats(allow_nan=True, allow_infinity=True),
    _SPECIAL_FLOATS,
    st.text(max_size=8),
    st.sampled_from(["box", "table", "finger", "hand", "arm", "none", "exact", "pyramid:4", "floor", "pusher"]),
)
JUNK = st.recursive(
    _LEAVES,
    lambda children: st.one_of(
        st.lists(children, max_size=4),
        st.dictionaries(st.text(max_size=6), children, max_size=3),
    ),
    max_leaves=8,
)
_KEYS = st.one_of(
    st.text(max_size=10),
    st.sampled_from(["mass", "com", "wrench", "twist", "origin", "robot", "jacobian", "mu", "normal", "point", "body", "other"]),
)


def _paths(node: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    out = [prefix]
    if isinstance(node, dict):
        for key, value in node.items():
            out += _paths(value, (*prefix, key))
    elif isinstance(node, list):
        for index, value in enumerate(node):
            out += _paths(value, (*prefix, index))
    return out


def _at(data: Any, path: tuple[Any, ...]) -> Any:
    for part in path:
        data = data[part]
    return data


@st.composite
def mutated_scenes(draw: st.DrawFn) -> dict[str, Any]:
    data = copy.deepcopy(draw(st.sampled_from([scene_2d(), scene_3d(), {**scene_3d(), "friction": "none"}])))
    for _ in range(draw(st.integers(min_value=1, max_value=3))):
        paths = [p for p in _paths(data) if p]  # never the root: it stays a mapping
        path = draw(st.sampled_from(paths))
        parent = _at(data, path[:-1])
        target = _at(data, path)
        operation = draw(st.sampled_from(["drop", "insert", "replace", *["number"] * 5]))
        if operation == "number":
            # Most junk fails validation at once; a changed number often loads and reaches the solver.
            numbers = [p for p in paths if isinstance(_at(data, p), (int, float)) and not isinstance(_at(data, p), bool)]
            if numbers:
                path = draw(st.sampled_from(numbers))
                _at(data, path[:-1])[path[-1]] = draw(_NUMBERS)
        elif operation == "drop":
            del parent[path[-1]]
        elif operation == "insert" and isinstance(target, dict):
            target[draw(_KEYS)] = draw(JUNK)
        elif operation == "insert" and isinstance(target, list):
            target.insert(draw(st.integers(min_value=0, max_value=len(target))), draw(JUNK))
        else:
            parent[path[-1]] = draw(JUNK)
    return data


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")
@pytest.mark.filterwarnings("ignore:invalid value encountered:RuntimeWarning")
@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutated_scenes())
def test_mutated_scene_raises_only_library_errors(data: dict[str, Any]) -> None:
    try:
        scene = qs.load_scene(data)
    except qs.SceneError as err:
        event("SceneError")
        assert isinstance(err.field, str)
        assert str(err)
        return
    assert isinstance(scene, qs.Scene)
    try:
        # The frictionless LP: fast and deterministic; a scene with mu > 0 must make it
        # raise QuasistaticError (not solve it silently, not crash).
        solution = qs.solve(scene, method="lp")
    except qs.QuasistaticError:
        event("solve raised QuasistaticError")
        return
    assert isinstance(solution, qs.Solution)
    event(f"solved: {solution.status}")
    assert solution.status in ("solved", "ambiguous", "jammed", "unstable", "failed")


def test_a_missing_scene_file_in_a_deep_folder_is_named_by_its_end(tmp_path: Any) -> None:
    """The value is cut to 80 characters; for a path the cut is at the start, so the file's name still shows."""
    path = tmp_path.joinpath(*["deep-folder"] * 12, "my_scene.yaml")
    with pytest.raises(qs.SceneError) as info:
        qs.load_scene(path)
    message = str(info.value)
    assert "my_scene.yaml'" in message and "'..." in message and len(message) < 200, message
