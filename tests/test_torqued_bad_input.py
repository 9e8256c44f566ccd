"""Hostile input to the torque models and the torqued solver: clear errors, never NaN."""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude import ConstantTorque, GravityGradient, InputError, TorquedSolver, UserTorque
from attitude.torques.solver import propagate_batch

INERTIA = [100.0, 200.0, 300.0]
M0 = [1.0, 2.0, 3.0]


def circular(t):
    t = np.asarray(t, dtype=float)
    return 7e6 * np.stack([np.cos(1e-3 * t), np.sin(1e-3 * t), 0 * t], axis=-1)


def _solve(torques, **options):
    solver = TorquedSolver(INERTIA, M0, torques=torques, **options)
    return solver.attitude_quaternion([10.0, 20.0])


@pytest.mark.parametrize(
    "position, message",
    [
        (lambda t: np.zeros(3), "returned shape"),
        (lambda t: np.full((*np.shape(t), 3), np.nan), "finite"),
        (lambda t: np.zeros((*np.shape(t), 3)), "away from the centre"),
        (lambda t: "far away", "numeric|returned shape|could not"),
    ],
)
def test_bad_positions_are_refused_with_the_time(position, message):
    with pytest.raises((InputError, ValueError), match=message):
        _solve([GravityGradient(position)])


@pytest.mark.parametrize("mu", [0.0, -3.986e14, math.nan, math.inf])
def test_bad_gravitational_parameter(mu):
    with pytest.raises(InputError, match="mu"):
        GravityGradient(circular, mu=mu)


def test_position_must_be_callable_or_an_orbit():
    with pytest.raises(InputError, match="callable"):
        GravityGradient([7e6, 0.0, 0.0])


def test_orbit_without_epoch():
    class Orbit:
        def position(self, times):
            return np.zeros((np.size(times), 3))

    with pytest.raises(InputError, match="epoch"):
        GravityGradient(Orbit())


@pytest.mark.parametrize(
    "args, message",
    [
        (([1.0, 0.0], 0.0, 1.0), "3-vector"),
        (([1.0, 0.0, math.nan], 0.0, 1.0), "finite"),
        (([1.0, 0.0, 0.0], 5.0, 5.0), "after start"),
        (([1.0, 0.0, 0.0], 5.0, math.nan), "after start|finite"),
        (([1.0, 0.0, 0.0], math.inf, 7.0), "finite"),
    ],
)
def test_bad_constant_torques(args, message):
    with pytest.raises(InputError, match=message):
        ConstantTorque(*args)


def test_constant_torque_frame_is_checked():
    with pytest.raises(InputError, match="frame"):
        ConstantTorque([1.0, 0.0, 0.0], 0.0, 1.0, frame="orbital")


def test_constant_torque_accepts_quantities():
    from astropy import units as u

    burn = ConstantTorque([1.0, 0.0, 0.0] * u.mN * u.m, 0.0 * u.s, 1.0 * u.min)
    assert burn.torque.tolist() == [1e-3, 0.0, 0.0] and burn.stop == 60.0
    with pytest.raises(InputError, match="unit"):
        ConstantTorque([1.0, 0.0, 0.0] * u.kg, 0.0, 1.0)


@pytest.mark.parametrize(
    "function, message",
    [
        (lambda t, attitude, ω: [1.0, 2.0], "shape"),
        (lambda t, attitude, ω: [1.0, math.nan, 0.0], "finite"),
        (lambda t, attitude, ω: [1.0, math.inf, 0.0], "finite"),
    ],
)
def test_bad_user_torques_name_the_function_and_time(function, message):
    with pytest.raises(InputError, match=message):
        _solve([UserTorque(function, name="thruster_model")])


def test_user_torque_errors_propagate_as_they_are():
    def broken(t, attitude, ω):
        raise RuntimeError("the user's model failed")

    with pytest.raises(RuntimeError, match="user's model"):
        _solve([broken])


@pytest.mark.parametrize("item", ["gravity", 3.0, None])
def test_torque_list_items_are_checked(item):
    with pytest.raises(InputError, match="torques"):
        TorquedSolver(INERTIA, M0, torques=[item])


@pytest.mark.parametrize("step", [0.0, -1.0, math.nan, math.inf])
def test_bad_steps(step):
    with pytest.raises(InputError, match="step"):
        TorquedSolver(INERTIA, M0, torques=[GravityGradient(circular)], step=step)


def test_order_and_method_are_checked():
    gg = GravityGradient(circular)
    with pytest.raises(InputError, match="order"):
        TorquedSolver(INERTIA, M0, torques=[gg], order=3)
    with pytest.raises(InputError, match="method"):
        TorquedSolver(INERTIA, M0, torques=[gg], method="rk4")
    with pytest.raises(InputError, match="order 4, not 2"):
        TorquedSolver(INERTIA, M0, torques=[gg], method="aba1064", order=2)
    # order 6 needs torques independent of ω; a damper is refused, with the way out.
    with pytest.raises(InputError, match="order 2 or 4"):
        TorquedSolver(INERTIA, M0, torques=[lambda t, a, ω: -ω], order=6)


def test_accuracy_needs_a_span_and_excludes_a_step():
    gg = GravityGradient(circular)
    with pytest.raises(InputError, match="span"):
        TorquedSolver(INERTIA, M0, torques=[gg], accuracy=1e-6)
    with pytest.raises(InputError, match="either step or accuracy"):
        TorquedSolver(INERTIA, M0, torques=[gg], accuracy=1e-6, span=100.0, step=1.0)
    for accuracy in (0.0, -1.0, math.nan):
        with pytest.raises(InputError, match="accuracy"):
            TorquedSolver(INERTIA, M0, torques=[gg], accuracy=accuracy, span=100.0)
    with pytest.raises(InputError, match="span"):
        TorquedSolver(INERTIA, M0, torques=[gg], accuracy=1e-6, span=-5.0)


def test_a_step_search_that_would_run_away_is_refused(monkeypatch):
    """A torque that spins the body up to 3e5 rad/s: the search shrinks the step try
    after try, and each try runs the span twice.  Past the search's cap of steps over
    the span it refuses, naming the accuracy, the step and the last estimate, instead
    of running for hours (the cap lowered here so that the test is quick; the scenario
    layer refuses such a burn before any search, test_check_refuses_what_run_refuses)."""
    import attitude.torques.solver as torqued_solver

    monkeypatch.setattr(torqued_solver, "MAX_STEPS", 2e3)
    spin_up = ConstantTorque([0.0, 0.0, 1e4], 0.0, math.inf)
    message = (
        r"accuracy: 1e-06 rad over 100 s would need a step below [\d.e-]+ s, more than "
        r"2000 steps; the estimate was [\d.e+-]+ rad at [\d.e-]+ s: give a step"
    )
    with pytest.raises(InputError, match=message):
        TorquedSolver(
            [1.0, 2.0, 3.0], [0.1, 0.2, 0.3], None, 0.0, [spin_up], accuracy=1e-6, span=100.0
        )


def test_times_before_t0_and_bad_times():
    solver = TorquedSolver(INERTIA, M0, t0=100.0, torques=[GravityGradient(circular)])
    with pytest.raises(InputError, match="t0"):
        solver.attitude(99.0)
    with pytest.raises(InputError, match="finite"):
        solver.angular_momentum([150.0, math.nan])
    with pytest.raises(InputError, match="1-D"):
        solver.attitude(np.full((2, 2), 150.0))


def test_the_solver_inputs_are_those_of_euler_solver():
    gg = GravityGradient(circular)
    with pytest.raises(InputError, match="positive"):
        TorquedSolver([100.0, -1.0, 300.0], M0, torques=[gg])
    with pytest.raises(InputError, match="angular_momentum"):
        TorquedSolver(INERTIA, [1.0, 2.0], torques=[gg])
    with pytest.raises(InputError, match="Rotation"):
        TorquedSolver(INERTIA, M0, attitude=[1.0, 0.0, 0.0, 0.0], torques=[gg])


def test_step_longer_than_the_span_and_a_resting_body():
    gg = GravityGradient(circular)
    solver = TorquedSolver(
        INERTIA, [0.0, 0.0, 0.0], Rotation.from_rotvec([0.1, 0.2, 0.3]), torques=[gg], step=1e4
    )
    q = solver.attitude_quaternion([0.0, 1.0, 50.0])
    assert np.all(np.isfinite(q))
    # At rest in a gradient: it starts to turn, slowly.
    assert np.linalg.norm(solver.angular_momentum(50.0)) > 0.0


def test_absurd_magnitudes_stay_finite():
    gg = GravityGradient(circular)
    tiny = TorquedSolver([1e-6, 2e-6, 3e-6], [1e-9, 2e-9, 3e-9], torques=[gg], step=1.0)
    huge = TorquedSolver([1e9, 2e9, 3e9], [1e8, 2e8, 3e8], torques=[gg], step=1.0)
    for solver in (tiny, huge):
        assert np.all(np.isfinite(solver.attitude_quaternion([0.5, 3.0])))


def test_batch_input_is_checked():
    gg = GravityGradient(circular)
    with pytest.raises(InputError, match="shape"):
        propagate_batch(INERTIA, M0, None, 0.0, [1.0], [gg])
    with pytest.raises(InputError, match="inertia"):
        propagate_batch([[1.0, 2.0, 3.0]] * 2, [M0] * 3, None, 0.0, [1.0], [gg])
    with pytest.raises(InputError, match="increasing"):
        propagate_batch(INERTIA, [M0], None, 0.0, [5.0, 1.0], [gg])


def test_a_huge_span_is_refused_not_hung():
    solver = TorquedSolver(INERTIA, M0, torques=[GravityGradient(circular)], step=1.0)
    with pytest.raises(InputError, match="steps"):
        solver.attitude(1e12)
    assert np.all(np.isfinite(solver.attitude_quaternion(3.0)))  # still usable after


@pytest.mark.parametrize("accuracy", [1e-300, 1e-13, 0.5, 1e300])
def test_an_accuracy_no_search_can_meet_is_refused_at_once(accuracy):
    """The range of the file's ``[torques] accuracy`` (1e-12 to 0.1 rad): below it the
    estimate is rounding and the search would shrink the step for minutes."""
    with pytest.raises(InputError, match=r"accuracy must be between 1e-12 and 0\.1 rad"):
        TorquedSolver(
            INERTIA, M0, torques=[GravityGradient(circular)], accuracy=accuracy, span=100.0
        )


@pytest.mark.parametrize(
    "torques",
    [
        [GravityGradient(circular, mu=1e300)],
        [
            UserTorque(
                lambda t, a, ω: np.array([1e300, 0.0, 0.0]), depends_on_angular_velocity=False
            )
        ],
        [UserTorque(lambda t, a, ω: np.array([1e300, 0.0, 0.0]))],
        [ConstantTorque([0.0, 1e300, 0.0], 0.0, 5.0)],
    ],
    ids=["mu 1e300", "user torque 1e300", "damper-like 1e300", "burn 1e300"],
)
def test_a_torque_of_1e300_is_an_input_error_not_a_numpy_warning(torques):
    """The momentum would leave the float range (or turn faster than float seconds
    follow) within a step: one InputError naming the rate and the time, no warning."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a RuntimeWarning would fail the test
        for options in ({"step": 10.0}, {}):
            solver = TorquedSolver(INERTIA, M0, torques=torques, **options)
            with pytest.raises(InputError, match=r"the torques spin the body up to .* by t = "):
                solver.attitude_quaternion([5.0, 100.0])
        with pytest.raises(InputError, match=r"the torques spin the body up to"):
            propagate_batch(INERTIA, [M0], None, 0.0, [5.0, 100.0], torques, step=10.0)
