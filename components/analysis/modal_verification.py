"""Check the linearised modes against the nonlinear model's free response after an impulse.

For every underdamped (oscillatory) mode of :func:`components.analysis.modes.drivetrain_modes`:

1. start the monolithic solver (:func:`components.reference.solver.simulate_monolithic`,
   the nonlinear CFS model) from the static equilibrium at constant rotor speed,
   plus an impulse: an initial deviation-speed perturbation along the velocity part
   of the mode's complex shape, scaled so that the linear prediction changes no
   contact force or shaft torque by more than ``amplitude`` (default 1 %) of its
   static value;
2. rebuild the deviation state ``x = [q, v]`` from the recorded deflections, shaft
   torques and body speeds, and project it on the mode with the left eigenvector,
   ``eta(t) = psi^H (x(t) - x_eq)`` - for the linear system exactly
   ``eta0 exp(lambda t)``;
3. find the spectral peak of the complex ``eta`` (zero-padded FFT, parabolic
   interpolation): it lies at ``Im(lambda) / (2 pi)``, the damped frequency.

A real response signal would not do for strongly damped modes: the spectrum of a
decaying real oscillation peaks at ``f_n sqrt(1 - 2 zeta^2)`` (displacement) or
``f_n`` (velocity), e.g. 5 % away from the damped frequency at zeta = 0.3.

Each mode gets its own record: sampled at ``samples_per_period`` points per damped
period and long enough (``decay_lengths / sigma``, ``sigma = -Re(lambda)``) for the
modal coordinate to die out, so no leakage window is needed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..errors import SolverError
from ..model.drivetrain import Drivetrain
from ..model.signals import deflection_name
from ..model.wind import ConstantSpeed
from ..reference.results import SimulationResult
from ..reference.solver import SolverSettings, simulate_monolithic
from ..validation import positive
from .equilibrium import OperatingPoint
from .modes import DrivetrainModalAnalysis, drivetrain_modes
from .spectrum import spectral_peak_hz


@dataclass(frozen=True)
class FreeResponseCheck:
    """Damped frequency of one mode, linear model vs nonlinear free response.

    Attributes
    ----------
    mode : int
        Mode index (1-based, as in the modal table).
    damped_frequency_hz : float
        ``Im(lambda) / (2 pi)`` of the linearised model [Hz].
    damping_ratio : float
        ``-Re(lambda) / |lambda|`` [-].
    spectral_peak_hz : float
        Peak of the spectrum of the simulated modal coordinate [Hz].
    relative_error : float
        ``(peak - damped) / damped`` [-].
    record_s : float
        Length of the simulated record [s].
    sample_interval_s : float
        Output interval of the record [s].
    wall_time_s : float
        Solver wall time of the record [s].
    """

    mode: int
    damped_frequency_hz: float
    damping_ratio: float
    spectral_peak_hz: float
    relative_error: float
    record_s: float
    sample_interval_s: float
    wall_time_s: float

    def as_dict(self) -> dict[str, float]:
        """Plain dict (JSON-ready)."""
        return dict(self.__dict__)


def deviation_state(result: SimulationResult, analysis: DrivetrainModalAnalysis) -> np.ndarray:
    """Deviation state ``[q, v]`` of every sample, rebuilt from a monolithic result.

    ``v = omega_body - kappa omega_rotor``; ``q`` solves ``[A; S] q = [delta; s]`` in
    the least-squares sense, with the recorded mesh deflections ``delta`` and the shaft
    twists ``s = (T - c S v) / k`` from the recorded shaft torques.

    Returns
    -------
    ndarray, shape (N, 2 n_dof)
    """
    a = analysis.model.assembly
    d = np.stack([result[deflection_name(name)] for name in a.mesh_names], axis=1)
    speeds = np.stack([result[f"{b}.omega"] for b in a.dof_names], axis=1)
    v = speeds - np.outer(result["omega_rotor"], a.kinematic_ratio)
    torque = np.stack([result[f"{s}.torque"] for s in a.shaft_names], axis=1)
    twist = (torque - a.shaft_c * (v @ a.S.T)) / a.shaft_k
    g = np.vstack([a.A, a.S])
    q = np.linalg.lstsq(g, np.hstack([d, twist]).T, rcond=None)[0].T
    return np.hstack([q, v])


def _loaded(drivetrain: Drivetrain, torque_nm: float) -> Drivetrain:
    """The drivetrain with a constant output torque (no load events)."""
    if drivetrain.generator is not None:
        return drivetrain.with_generator(counter_torque_nm=torque_nm, events=())
    return replace(drivetrain, output_torque_nm=torque_nm, output_events=())


def free_response_check(
    drivetrain: Drivetrain,
    operating_point: OperatingPoint,
    analysis: DrivetrainModalAnalysis | None = None,
    amplitude: float = 0.01,
    samples_per_period: float = 40.0,
    decay_lengths: float = 12.0,
    max_record_s: float = 30.0,
    settings: SolverSettings | None = None,
) -> list[FreeResponseCheck]:
    """Compare every underdamped mode's damped frequency with the simulated free response.

    Parameters
    ----------
    drivetrain : Drivetrain
        The drivetrain (its load events are ignored; the load is the operating point's).
    operating_point : OperatingPoint
        Constant rotor speed and output torque.
    analysis : DrivetrainModalAnalysis, optional
        The modal analysis at that point (computed if not given).
    amplitude : float
        Largest relative change of a contact force or shaft torque the impulse may
        cause in the linear prediction [-] (small: the check is about the linearisation).
    samples_per_period : float
        Output samples per damped period of the mode [-].
    decay_lengths : float
        Record length in decay times ``1 / sigma`` [-].
    max_record_s : float
        Upper bound of a record [s].
    settings : SolverSettings, optional
        Monolithic solver tolerances (default: tighter than the solver default).

    Returns
    -------
    list of FreeResponseCheck
        One per underdamped mode (repeated eigenvalues, e.g. planet-mode pairs, once
        per mode), in mode order; empty if every mode is overdamped.
    """
    amp = positive("amplitude", amplitude)
    spp = positive("samples_per_period", samples_per_period)
    positive("decay_lengths", decay_lengths)
    positive("max_record_s", max_record_s)
    if analysis is None:
        analysis = drivetrain_modes(drivetrain, operating_point)
    settings = settings or SolverSettings(rtol=1e-9, atol_angle_rad=1e-13, atol_speed_rad_s=1e-10)
    loaded = _loaded(drivetrain, operating_point.output_torque_nm)
    driver = ConstantSpeed(operating_point.rotor_speed_rad_s)
    a = analysis.model.assembly
    eq = analysis.model.equilibrium
    ss = analysis.state_space
    n = a.n_dof
    checks = []
    for dm in analysis.underdamped:
        lam = complex(dm.mode.eigenvalue)
        j = int(dm.mode.eigen_index)
        sigma = -lam.real
        f_d = lam.imag / (2.0 * math.pi)
        h = 1.0 / (spp * f_d)
        record = min(decay_lengths / sigma, max_record_s)
        # impulse: deviation speeds along the mode's velocity shape
        phi_v = ss.right[n:, j]
        v0 = np.real(phi_v / phi_v[np.argmax(np.abs(phi_v))])
        delta = np.concatenate([np.zeros(n), v0])
        # linear prediction over one damped period (enough for the peak) -> scale the impulse
        t_lin = np.linspace(0.0, min(record, 1.5 / f_d), 400)
        coef = ss.left.conj().T @ delta
        x_lin = np.real(ss.right @ (coef[:, None] * np.exp(np.outer(ss.eigenvalues, t_lin))))
        d_force = eq.mesh_stiffness_n_per_m[:, None] * (a.A @ x_lin[:n])
        d_torque = a.shaft_k[:, None] * (a.S @ x_lin[:n])
        ratio = max(
            float((np.abs(d_force).max(axis=1) / np.abs(eq.contact_force_n)).max()),
            float((np.abs(d_torque).max(axis=1) / np.abs(eq.shaft_torque_nm)).max()),
        )
        x0 = eq.state + (amp / ratio) * delta
        result = simulate_monolithic(loaded, driver, record, output_interval_s=h, settings=settings, initial_state=x0)
        if not result.complete:
            raise SolverError(f"free response of mode {dm.mode.index}: {result.message}", float(result.time_s[-1]))
        eta = (deviation_state(result, analysis) - eq.state) @ ss.left[:, j].conj()
        peak = spectral_peak_hz(eta, h)
        checks.append(
            FreeResponseCheck(
                mode=dm.mode.index,
                damped_frequency_hz=f_d,
                damping_ratio=dm.mode.damping_ratio,
                spectral_peak_hz=peak,
                relative_error=(peak - f_d) / f_d,
                record_s=record,
                sample_interval_s=h,
                wall_time_s=result.wall_time_s,
            )
        )
    return checks
