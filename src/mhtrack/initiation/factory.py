"""P2's initiators by name: the one mapping from :data:`mhtrack.names.INITIATORS` to the
classes (:mod:`mhtrack.build` and the MHT's initiator birth both build through it)."""

from __future__ import annotations

from typing import Any

from mhtrack.initiation.hough import HoughInitiator
from mhtrack.initiation.logic import LogicInitiator

#: Initiator name (:data:`mhtrack.names.INITIATORS`) → its class and the constructor
#: arguments that make the named variant (P2 §2.1, §3.2: the modified methods add the
#: angle limit θ; the plain logic has none, the plain Hough keeps θ for its lines).
INITIATOR_CLASSES: dict[str, tuple[type[Any], dict[str, Any]]] = {
    "logic": (LogicInitiator, {"angle_limit_deg": None}),
    "modified-logic": (LogicInitiator, {}),
    "hough": (HoughInitiator, {"modified": False}),
    "modified-hough": (HoughInitiator, {"modified": True}),
}


def make_initiator(method: str, *, theta_deg: float = 20.0,
                   **params: Any) -> LogicInitiator | HoughInitiator:
    """The initiator named ``method`` (:data:`INITIATOR_CLASSES`); ``theta_deg`` is P2's
    angle limit for the modified methods (ignored by the plain logic); ``params`` go to
    the constructor (e.g. ``gate_radius``, ``v_min``, ``v_max``)."""
    if method not in INITIATOR_CLASSES:
        raise ValueError(f"unknown initiation method {method!r} "
                         f"(expected {', '.join(INITIATOR_CLASSES)})")
    cls, variant = INITIATOR_CLASSES[method]
    return cls(**{"angle_limit_deg": theta_deg, **variant}, **params)  # type: ignore[no-any-return]


__all__ = ["INITIATOR_CLASSES", "make_initiator"]
