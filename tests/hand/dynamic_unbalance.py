"""Fig. 32, eq. 87-88, worked by hand. The rotor's angular velocity in its basis
{e1, e2, e3} is Omega = (psi' sin phi, psi' cos phi, omega), so
T = [(I1 sin^2 phi + I2 cos^2 phi + I_Gb) psi'^2 + 2 I23 omega cos(phi) psi' + I3 omega^2]/2
and Lagrange's equation of psi is eq. 87. With I1 = I2 = I_Gr (eq. 88) the inertia about
the vertical is I_Gr + I_Gb: omega_n = sqrt(k_t/(I_Gr + I_Gb)), and the steady response to
I23 omega^2 sin(omega t) is psi = A sin(omega t), A = I23 omega^2/(k_t - (I_Gr + I_Gb)
omega^2). The motor's torque about e3 is d/dt(dT/dphi') - dT/dphi with phi' = omega:
I23 cos(phi) psi'' + (I2 - I1) sin(phi) cos(phi) psi'^2."""
import numpy as np

EQUILIBRIA = (1, 1)
MISPRINTS = set()


def relations(v):
    """Eq. 88's case, where the linearization has constant coefficients: I2 = I1 (with
    I1 != I2 the system is parametric and has no equilibrium to linearize about)."""
    return {**v, "I2": v["I1"]}


def frequencies(v):
    return [np.sqrt(v["k_t"] / (v["I1"] + v["I_Gb"]))]


def steady_amplitude(v):
    return v["I23"] * v["omega"] ** 2 / (v["k_t"] - (v["I1"] + v["I_Gb"]) * v["omega"] ** 2)


def motor_torque(v, t, psi_d, psi_dd):
    phi = v["omega"] * t
    return (v["I23"] * np.cos(phi) * psi_dd
            + (v["I2"] - v["I1"]) * np.sin(phi) * np.cos(phi) * psi_d**2)
