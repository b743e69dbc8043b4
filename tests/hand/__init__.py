"""Hand-derived facts, one module per mechanism (named as the system), written
independently of the code under test. Each module defines:

- ``frequencies(v) -> list[float]``: undamped natural angular frequencies (rad/s) at the
  operating equilibrium for parameter values ``v``, worked out by hand;
- ``EQUILIBRIA = (total, stable)``: equilibria within one period of each angle, counted by
  hand at the default parameters (total None where only the stable ones are counted);
- ``MISPRINTS``: labels of printed formulas that the hand derivation shows to be wrong,
  each with the reason in a comment;
- optionally ``relations(v) -> dict``: the values tied by the relations under which the
  mechanism has an equilibrium to linearize (e.g. I2 = I1 of eq. 88);
- optionally ``valid(v) -> bool``: whether random parameter values keep the mechanism
  assembled with an equilibrium near the operating point.
"""
import importlib
import pkgutil


def facts() -> dict:
    return {info.name: importlib.import_module(f"{__name__}.{info.name}")
            for info in pkgutil.iter_modules(__path__)}
