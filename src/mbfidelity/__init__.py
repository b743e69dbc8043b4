"""mbfidelity: cross-validation of multibody simulators against exact models of the
mechanisms of a monograph on mechanical vibrations."""
__version__ = "0.1.0"

#: the Python API (mbfidelity/api.py), imported on first use: `import mbfidelity` stays light
_API = ("analyze", "compare", "run", "check", "diff", "export")


def __getattr__(name: str):
    if name in _API:
        from . import api

        return getattr(api, name)
    raise AttributeError(f"module 'mbfidelity' has no attribute {name!r}")
