"""The protocol every effect family of ``rwadist diagnose`` follows, and the registry that lists them.

A family is one module of this package holding one dataclass decorated with :func:`register`; the
search (:mod:`rwadist.diagnose.search`) sees only the protocol, never a concrete class.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING, ClassVar, Protocol, runtime_checkable

if TYPE_CHECKING:
    from ..engine import Context
    from ..state import State


@runtime_checkable
class Effect(Protocol):
    """What the search needs from an effect.

    kind : the model file's ``kind`` of the effect.
    channels : the channels (names of :data:`rwadist.units.CHANNELS`) the effect acts on.
    order : its rank in the registry (candidates of lower ``order`` come first; the search's ranking is
        a stable sort, so this decides ties).

    ``candidates(ctx, state, runs)`` (a static method) returns fitted hypotheses proposed from the
    residual on ``runs``; ``fit`` (static, family-specific arguments) fits one.
    """

    kind: str
    order: ClassVar[int]

    @property
    def channels(self) -> tuple: ...

    @staticmethod
    def candidates(ctx: Context, state: State, runs) -> list: ...

    def apply(self, state: State) -> State:
        """A new state with this effect in it (``state`` is not changed): :meth:`State.plus`, and what the effect
        changes besides (the model's harmonics, the noise estimate)."""
        ...

    # optional: ``contribute(parts)`` puts the effect's part of the prediction in ``parts`` (a
    # :class:`~rwadist.diagnose.state.Prediction`: an amplitude law, a floor, a resonance, ...); the state's
    # prediction is every effect's part, in order

    def refit(self, ctx: Context, state: State) -> "Effect":
        """This effect refitted on every run (``ctx.runs``) in ``state``; itself when that fit fails."""
        ...

    def params(self) -> dict:
        """Parameters (JSON types), for the report and the model file."""
        ...

    def to_schema(self) -> dict:
        """The model file's ``effects`` entry: ``{"kind", **params(), "channel"}``."""
        ...


#: kind -> effect class, filled by :func:`register` as the family modules are imported.
REGISTRY: dict = {}


def register(order: int):
    """Class decorator: add an effect family to :data:`REGISTRY` at rank ``order`` (unique)."""

    def deco(cls):
        kind = cls.__dataclass_fields__["kind"].default
        clash = [k for k, c in REGISTRY.items() if c.order == order and c is not cls]
        if clash:
            raise ValueError(f"effect family {cls.__name__}: order {order} already taken by {clash}")
        cls.order = order
        REGISTRY[kind] = cls
        return cls

    return deco


def schema_entry(effect) -> dict:
    """``{"kind", **params(), "channel"}`` of ``effect``: the shared body of every family's ``to_schema``."""
    return {"kind": effect.kind, **effect.params(), "channel": list(effect.channels)}


def finite_or_none(x) -> float | None:
    """``x`` as a float, or None (the model file's null: a statistic that could not be computed) for NaN and the
    infinities, which JSON cannot hold and the schema refuses (:func:`rwadist.schema.statistic`)."""
    x = float(x)
    return x if math.isfinite(x) else None
