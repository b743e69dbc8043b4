"""The multibody community's benchmark problems, beside the monograph's mechanisms: the
IFToMM benchmark of multibody system dynamics, group A (González, Dopico, Lugrís,
Cuadrado, "A benchmarking system for MBS simulation software: problem standardization and
performance measurement", Multibody System Dynamics 16:179-190, 2006), and Andrews'
squeezing mechanism of Hairer and Wanner's test problems. Each module cites its published
specification (parameters, initial state, duration) and the values its sources publish
(`System.published`), which `analyze` compares with the reference.
"""
