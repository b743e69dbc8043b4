"""Engine-neutral descriptions of continua (distributed mass and stiffness), for the engines'
own flexible elements (simulators/base.py, contract point 12).

A `Beam` is data, like a `Mechanism`: the straight Euler-Bernoulli beam of the monograph's
§6.1 (Fig. 17), lying along the world x axis from x = 0 to x = l, bending in the x-y plane,
with bending stiffness EI, mass per length rho, and a point mass m at x = a (the block of
Fig. 17; m = 0: the bare beam). Supports: simply supported, a pin at x = 0 and a roller at
x = l (deflection zero, moment zero at both ends; in small vibration the roller's free axial
motion decouples from bending). Gravity is off: the modal work is about the straight
equilibrium, where the block's weight only sets a static deflection.

The module's name starts with an underscore so that the catalog's discovery (one module
per mechanism, systems/__init__.py) passes it by: it describes no mechanism of its own.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Mapping

#: the only support case described so far (pin at x = 0, roller at x = l)
SIMPLY_SUPPORTED = "simply supported"
SUPPORTS = (SIMPLY_SUPPORTED,)

#: parameter names as in §6.1 (Fig. 17) -> Beam field
PARAMETER_FIELDS = {"l": "length", "EI": "EI", "rho": "rho", "m": "point_mass"}


@dataclass(frozen=True)
class Beam:
    """A straight beam with distributed mass and an optional point mass (§6.1, Fig. 17).

    length: l (m); EI: bending stiffness (N m^2); rho: mass per length (kg/m);
    point_mass: m (kg) at x = point_position = a (m), 0 < a < l; supports: SUPPORTS;
    gravity: always False here (modal work about the straight equilibrium)."""

    length: float = 1.0
    EI: float = 100.0
    rho: float = 1.0
    point_mass: float = 0.0
    point_position: float = 0.5
    supports: str = SIMPLY_SUPPORTED
    gravity: bool = False

    def __post_init__(self) -> None:
        for name in ("length", "EI", "rho"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"beam {name} must be a positive number, got {value}")
        if not (math.isfinite(self.point_mass) and self.point_mass >= 0):
            raise ValueError(f"beam point_mass must be >= 0, got {self.point_mass}")
        if not 0.0 < self.point_position < self.length:
            raise ValueError(f"the point mass must lie between the supports: a = "
                             f"{self.point_position}, l = {self.length}")
        if self.supports not in SUPPORTS:
            raise ValueError(f"supports {self.supports!r} not described; valid: {SUPPORTS}")
        if self.gravity:
            raise ValueError("a Beam is for modal work about the straight equilibrium: "
                             "gravity must be off")

    @property
    def c(self) -> float:
        """The point mass's position as a fraction of the span, a / l."""
        return self.point_position / self.length

    def node_of_point_mass(self, elements: int) -> int | None:
        """The index (0..N) of the node at x = a when the beam is cut into `elements`
        equal elements, or None when no node falls there (the point mass then has no node
        to sit on; for c = 1/2 any even N has one)."""
        if elements < 1:
            raise ValueError(f"a beam needs at least one element, got {elements}")
        position = self.c * elements
        node = round(position)
        return node if abs(position - node) <= 1e-9 * elements else None

    def as_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_parameters(cls, values: Mapping[str, float]) -> "Beam":
        """A beam from the §6.1 row's parameter names (l, EI, rho, m, c; a = c l), each
        defaulting to the catalog's value (l = 1, EI = 100, rho = 1, m = 0, c = 0.5)."""
        unknown = set(values) - set(PARAMETER_FIELDS) - {"c"}
        if unknown:
            raise ValueError(f"unknown beam parameter(s) {', '.join(sorted(unknown))}; valid: "
                             f"{', '.join([*PARAMETER_FIELDS, 'c'])}")
        fields = {PARAMETER_FIELDS[k]: float(v) for k, v in values.items() if k != "c"}
        length = fields.get("length", cls.length)
        c = float(values.get("c", 0.5))
        return cls(**fields, point_position=c * length)
