"""mbfidelity: cross-validation of multibody simulators against exact models of the
mechanisms of a monograph on mechanical vibrations."""
__version__ = "0.1.0"
