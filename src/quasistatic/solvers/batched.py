"""The default certified method on a stack of planar problems of one shape (a sweep's chunk), decided together.

Not a registry method: :func:`certify_stack` answers only the points whose answer it proves exactly as the
``certified`` method would (:mod:`.certify.batched`), and says which; the caller solves the rest one by one.
"""

from __future__ import annotations

from ..laws.stacked import StackedLaws
from .certify.batched import BatchedMotions, certify_batch
from .result import force_claim

__all__ = ["BatchedMotions", "certify_stack", "solved_message"]


def solved_message(indeterminate: bool) -> str:
    """The message of a decided point: the certified method's for one motion, with what is known of its forces."""
    return "solved: one motion" + force_claim(indeterminate)


def certify_stack(laws: StackedLaws) -> BatchedMotions:
    """Each point's only motion (scene-relative twist and contact-frame forces) where it is proven, and whether its
    forces are indeterminate; ``decided`` False elsewhere. Every point must have the same contacts with friction."""
    return certify_batch(laws)
