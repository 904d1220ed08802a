"""A Solution in a notebook: ``_repr_html_`` shows the verdict, the proof and audit, each contact's mode in its
colour with its normal force and slip, the twists, and the bar chart of ``_repr_png_`` when matplotlib is there."""

from __future__ import annotations

import base64
import re
import sys
from pathlib import Path

import pytest

import quasistatic as qs
from quasistatic.viz import MODE_COLOURS

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.fixture(scope="module")
def lift() -> qs.Solution:
    return qs.solve(qs.load_scene(EXAMPLES / "two_finger_lift.yaml"))


def test_the_html_lists_every_contact_with_its_mode_colour_and_force(lift: qs.Solution) -> None:
    page = lift._repr_html_()
    assert lift.status == "solved" and "<b>solved: " in page and "proven; audit of the laws: passed" in page
    rows = re.findall(
        r"<tr><td>(\d+)</td><td>(\w+)</td><td>(\w+)</td><td><span style=\"color:(#\w+)\">&#9679;</span> (\w+)</td><td>([^<]*)</td>", page
    )
    assert [int(r[0]) for r in rows] == list(range(len(lift.contacts)))
    for row, contact in zip(rows, lift.contacts, strict=True):
        assert (row[1], row[2], row[4], row[3]) == (contact.body, contact.other, contact.mode, MODE_COLOURS[contact.mode])
        assert float(row[5].split()[0]) == pytest.approx(contact.normal_force, rel=1e-3, abs=1e-12)
    assert "<td>box</td><td>[0, 0.01, 0]</td>" in page


def test_the_html_embeds_the_chart_only_with_matplotlib(lift: qs.Solution, monkeypatch: pytest.MonkeyPatch) -> None:
    pytest.importorskip("matplotlib")
    embedded = re.search(r'src="data:image/png;base64,([^"]+)"', lift._repr_html_())
    assert embedded and base64.b64decode(embedded.group(1)) == lift._repr_png_()
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # as if the figures extra were not installed
    page = lift._repr_html_()
    assert "<img" not in page and "<table>" in page


def test_an_answer_without_a_motion_says_so() -> None:
    answer = qs.solve(qs.load_scene(EXAMPLES / "topple.yaml"))
    page = answer._repr_html_()
    assert answer.status == "unstable" and "<b>unstable: " in page and "no motion; proven" in page and "<table>" not in page
