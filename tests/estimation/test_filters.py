"""The estimation examples against the truth of their simulated runs: errors, and consistency (the
NEES of a consistent filter follows a chi-square distribution with the state's dimension)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import chi2

from cmdragons.estimation.filters import (
    EKFLocalisation,
    EKFSlam,
    EKFSteered,
    Lander,
    ParticleLocalisation,
    simulate_lander,
)
from cmdragons.estimation.models import (
    compose,
    compose_jacobians,
    invert,
    observation_to_landmark,
    observation_to_landmark_jacobians,
    observe,
    observe_jacobians,
    velocity_steer,
    velocity_steer_jacobians,
)
from cmdragons.estimation.simulate import simulate_run, simulate_steered_run


def numeric_jacobian(f, x: np.ndarray, eps: float = 1e-6) -> np.ndarray:  # type: ignore[no-untyped-def]
    x = np.asarray(x, dtype=np.float64)
    cols = []
    for k in range(len(x)):
        d = np.zeros_like(x)
        d[k] = eps
        cols.append((f(x + d) - f(x - d)) / (2 * eps))
    return np.stack(cols, axis=1)


def test_model_jacobians_match_finite_differences() -> None:
    a, b = np.array([1.0, -2.0, 0.7]), np.array([0.3, 0.2, -0.4])
    j1, j2 = compose_jacobians(a, b)
    assert np.allclose(j1, numeric_jacobian(lambda x: compose(x, b), a), atol=1e-6)
    assert np.allclose(j2, numeric_jacobian(lambda x: compose(a, x), b), atol=1e-6)
    assert np.allclose(compose(a, invert(a)), 0.0, atol=1e-12)
    lm = np.array([4.0, 1.0])
    jx, jl = observe_jacobians(a, lm)
    assert np.allclose(jx, numeric_jacobian(lambda x: observe(x, lm), a), atol=1e-6)
    assert np.allclose(jl, numeric_jacobian(lambda x: observe(a, x), lm), atol=1e-6)
    z = observe(a, lm)
    assert np.allclose(observation_to_landmark(a, z), lm)
    gx, gz = observation_to_landmark_jacobians(a, z)
    assert np.allclose(gx, numeric_jacobian(lambda x: observation_to_landmark(x, z), a), atol=1e-6)
    assert np.allclose(gz, numeric_jacobian(lambda x: observation_to_landmark(a, x), z), atol=1e-6)
    u, dt, wheelbase = np.array([1.5, 0.3]), 0.1, 0.5
    fx, fu = velocity_steer_jacobians(a, u, dt, wheelbase)
    assert np.allclose(fx, numeric_jacobian(lambda x: velocity_steer(x, u, dt, wheelbase), a), atol=1e-6)
    assert np.allclose(fu, numeric_jacobian(lambda x: velocity_steer(a, x, dt, wheelbase), u), atol=1e-6)


@pytest.mark.parametrize(("phi", "turn"), [(0.0, 0.0), (0.3, 1.5 * math.sin(0.3) / 0.5)])
def test_the_velocity_steer_model_drives_straight_and_turns_at_v_sin_phi_over_l(phi: float, turn: float) -> None:
    p = velocity_steer([1.0, 2.0, 0.5], [1.5, phi], 0.1, 0.5)
    assert p[2] == pytest.approx(0.5 + 0.1 * turn, abs=1e-12)  # rad
    assert math.hypot(p[0] - 1.0, p[1] - 2.0) == pytest.approx(0.15, abs=1e-12)  # m, along theta + phi
    assert math.atan2(p[1] - 2.0, p[0] - 1.0) == pytest.approx(0.5 + phi, abs=1e-12)


def test_the_lander_filter_beats_its_radar_and_is_consistent() -> None:
    lander = Lander()
    run = simulate_lander(lander, seed=1)
    late = slice(len(run["t"]) // 4, None)  # after the start's uncertainty settled
    radar_rms = float(np.sqrt(np.mean((run["radar"][late] - run["altitude"][late]) ** 2)))
    est_err = run["est_altitude"][late] - run["altitude"][late]
    assert float(np.sqrt(np.mean(est_err**2))) < 0.5 * radar_rms
    # altitude errors normalised by the filter's own sigma: about unit variance
    z = est_err / np.sqrt(run["var_altitude"][late])
    assert 0.5 < float(np.mean(z**2)) < 2.0
    assert run["altitude"][-1] <= 0.5 and abs(run["speed"][-1]) < 5.0  # it landed, slowly


def _start(run, seed: int = 0):  # type: ignore[no-untyped-def]
    """A start estimate drawn from its own covariance around the true start (a filter told it is
    unsure by P0 must be wrong by about that much, or its NEES says it is too careful)."""
    p0 = np.diag([0.01, 0.01, 0.001])
    return run.truth[0] + np.random.default_rng(100 + seed).multivariate_normal(np.zeros(3), p0), p0


@pytest.mark.slow
def test_ekf_localisation_nees_lies_within_its_chi_square_bounds() -> None:
    # the NEES averaged over N independent runs: within the two-sided 95% bounds of chi2(3N)/N
    n_runs, steps = 20, 300
    totals = np.zeros(steps)
    errors = []
    for seed in range(n_runs):
        run = simulate_run(seed=seed, steps=steps)
        x0, p0 = _start(run, seed)
        ekf = EKFLocalisation(run.landmarks, x0, p0, run.sensor_cov)
        for k in range(steps):
            ekf.predict(run.odometry[k], run.odometry_cov)
            ekf.update(run.sightings[k])
            totals[k] += ekf.nees(run.truth[k + 1])
            errors.append(math.hypot(*(ekf.pose[:2] - run.truth[k + 1][:2])))
    mean_nees = totals / n_runs
    lo, hi = chi2.ppf([0.025, 0.975], 3 * n_runs) / n_runs
    inside = np.mean((mean_nees >= lo) & (mean_nees <= hi))
    assert inside >= 0.9, (inside, lo, hi, float(np.mean(mean_nees)))
    assert float(np.median(errors)) < 0.1


@pytest.mark.slow
def test_the_steered_vehicle_ekf_is_consistent_and_beats_dead_reckoning() -> None:
    # the NEES averaged over N runs within the 95% bounds of chi2(3N)/N, as for EKF localisation
    n_runs, steps, wheelbase = 20, 300, 0.5
    totals = np.zeros(steps)
    errors, dead_reckoned = [], []
    for seed in range(n_runs):
        run = simulate_steered_run(seed=seed, steps=steps, wheelbase_m=wheelbase)
        x0, p0 = _start(run, seed)
        ekf = EKFSteered(run.landmarks, x0, p0, run.sensor_cov, run.dt_s, wheelbase)
        alone = x0
        for k in range(steps):
            ekf.predict(run.odometry[k], run.odometry_cov)
            ekf.update(run.sightings[k])
            alone = velocity_steer(alone, run.odometry[k], run.dt_s, wheelbase)
            totals[k] += ekf.nees(run.truth[k + 1])
            errors.append(math.dist(ekf.pose[:2], run.truth[k + 1][:2]))
            dead_reckoned.append(math.dist(alone[:2], run.truth[k + 1][:2]))
    mean_nees = totals / n_runs
    lo, hi = chi2.ppf([0.025, 0.975], 3 * n_runs) / n_runs
    inside = np.mean((mean_nees >= lo) & (mean_nees <= hi))
    assert inside >= 0.9, (inside, lo, hi, float(np.mean(mean_nees)))
    assert float(np.median(errors)) < 0.05  # m
    assert float(np.median(errors)) < 0.1 * float(np.median(dead_reckoned))


def test_ekf_slam_maps_the_landmarks_and_keeps_the_pose_consistent() -> None:
    run = simulate_run(seed=3, steps=600)
    x0, p0 = _start(run)
    slam = EKFSlam(len(run.landmarks), x0, p0, run.sensor_cov)
    nees_values = []
    for k in range(600):
        slam.predict(run.odometry[k], run.odometry_cov)
        slam.update(run.sightings[k])
        nees_values.append(slam.nees(run.truth[k + 1]))
    seen = np.flatnonzero(slam.known)
    assert len(seen) >= 10
    # the map's shape: distances between landmarks (the absolute frame carries the start's error)
    pairs = [(i, j) for i in seen for j in seen if i < j]
    shape = [abs(math.dist(slam.landmark(i), slam.landmark(j)) - math.dist(run.landmarks[i], run.landmarks[j]))
             for i, j in pairs]
    assert float(np.median(shape)) < 0.1
    assert math.dist(slam.pose[:2], run.truth[-1][:2]) < 0.5
    # one run: the pose's NEES averaged over time near its dimension, 3
    assert 1.0 < float(np.mean(nees_values)) < 6.0
    # the landmarks' own covariances say how far off they are (2 dof, averaged over the map)
    lm_nees = [float(e @ np.linalg.solve(slam.landmark_cov(i), e))
               for i, e in ((i, slam.landmark(i) - run.landmarks[i]) for i in seen)]
    assert 0.5 < float(np.mean(lm_nees)) < 5.0


@pytest.mark.parametrize("seed", [0, 1])
def test_particle_localisation_follows_the_vehicle(seed: int) -> None:
    run = simulate_run(seed=seed, steps=300)
    x0, p0 = _start(run)
    pf = ParticleLocalisation(run.landmarks, x0, p0, run.sensor_cov, n=500, seed=seed)
    ekf = EKFLocalisation(run.landmarks, x0, p0, run.sensor_cov)
    pf_err, ekf_err = [], []
    for k in range(300):
        for f in (pf, ekf):
            f.predict(run.odometry[k], run.odometry_cov)
            f.update(run.sightings[k])
        pf_err.append(math.dist(pf.pose[:2], run.truth[k + 1][:2]))
        ekf_err.append(math.dist(ekf.pose[:2], run.truth[k + 1][:2]))
    assert float(np.median(pf_err)) < 0.15
    assert float(np.median(pf_err)) < 2.0 * float(np.median(ekf_err)) + 0.02


def test_the_regularised_particle_filter_is_consistent_on_the_bench_s_run() -> None:
    # the bench's run (one sighting a step, odometry noisy in distance and heading), 500 particles,
    # five seeds: the NEES of the cloud's covariance about 3 (chi-square, 3 dof) and inside its 95%
    # interval about 95% of the steps; without the regularisation the same filter reads
    # overconfident. One seed alone varies too much to say (a mean NEES from 2.7 to 4.0 regularised).
    from cmdragons.bench.estimation import ODOMETRY_SIGMA, START_COV

    lo, hi = chi2.ppf([0.025, 0.975], 3)
    means: dict[float, list[float]] = {0.6: [], 0.0: []}
    inside, rms = [], []
    for seed in range(5):
        run = simulate_run(seed=seed, steps=1000, odometry_sigma=ODOMETRY_SIGMA, max_sightings=1)
        x0 = run.truth[0] + np.random.default_rng(seed).multivariate_normal(np.zeros(3), START_COV)
        for share in means:
            pf = ParticleLocalisation(run.landmarks, x0, START_COV, run.sensor_cov, n=500, seed=seed,
                                      bandwidth_share=share)
            values, errors = [], []
            for k in range(len(run.odometry)):
                pf.step(run.odometry[k], run.odometry_cov, run.sightings[k])
                values.append(pf.nees(run.truth[k + 1]))
                errors.append(math.dist(pf.pose[:2], run.truth[k + 1][:2]))
            v = np.array(values)
            means[share].append(float(np.mean(v)))
            if share > 0.0:
                inside.append(float(np.mean((v >= lo) & (v <= hi))))
                rms.append(float(np.sqrt(np.mean(np.square(errors)))))
    assert 2.0 < float(np.mean(means[0.6])) < 3.5
    assert float(np.mean(inside)) >= 0.92
    assert max(rms) < 0.05  # m
    assert float(np.mean(means[0.0])) > 3.5 and float(np.mean(means[0.0])) > float(np.mean(means[0.6]))


# --- the particle filter's kernels against their numpy reference ---------------------------------


def test_the_kernels_normal_deviates_are_standard_normal() -> None:
    from scipy import stats

    from cmdragons.estimation import _kernels as K

    zx, zf = K.ziggurat_tables()
    assert zx[1] == K.ZIGGURAT_TAIL and zx[-1] == 0.0 and np.all(np.diff(zx) < 0)
    z = K.normals(K.seed_stream(np.random.default_rng(3)), zx, zf, 400_000)
    assert abs(float(np.mean(z))) < 0.01 and abs(float(np.std(z)) - 1.0) < 0.01
    assert stats.kstest(z, "norm").pvalue > 0.001
    tail = np.abs(z[np.abs(z) > K.ZIGGURAT_TAIL])  # the ziggurat's tail, sampled apart
    assert stats.kstest(tail, lambda x: 1.0 - stats.norm.sf(x) / stats.norm.sf(K.ZIGGURAT_TAIL)).pvalue > 0.001
    u = K.uniforms(K.seed_stream(np.random.default_rng(3)), 100_000)
    assert 0.0 <= u.min() and u.max() < 1.0 and stats.kstest(u, "uniform").pvalue > 0.001


@pytest.mark.parametrize("cov", [np.diag([4e-4, 0.0, 2.5e-5]), np.zeros((3, 3)),
                                 np.array([[2.0, 0.5, 0.1], [0.5, 1.0, 0.2], [0.1, 0.2, 0.5]])])
def test_the_semi_definite_factor_reproduces_its_covariance(cov: np.ndarray) -> None:
    from cmdragons.estimation import _kernels as K

    low = K.psd_factor(cov)
    np.testing.assert_allclose(low @ low.T, cov, atol=1e-15)
    assert np.all(np.triu(low, 1) == 0.0)


@pytest.mark.parametrize("seed", [0, 1])
def test_the_particle_step_kernel_agrees_with_its_numpy_reference(seed: int) -> None:
    from cmdragons.bench.estimation import ODOMETRY_SIGMA, START_COV
    from cmdragons.estimation import _kernels as K
    from cmdragons.estimation import _reference as R

    run = simulate_run(seed=seed, steps=60, odometry_sigma=ODOMETRY_SIGMA, max_sightings=2)
    pf = ParticleLocalisation(run.landmarks, run.truth[0], START_COV, run.sensor_cov, n=300, seed=seed)
    assert pf.cloud.flags.c_contiguous  # one row per quantity, contiguous: the kernels' loops vectorise over it
    zx, zf = K.ziggurat_tables()
    resampled = 0
    for k in range(len(run.odometry)):
        p, w, s = pf.particles.copy(), pf.weights.copy(), pf.stream.copy()
        seen = pf._seen(run.sightings[k])
        ref = R.particle_step(p, w, run.odometry[k], run.odometry_cov, seen, pf.R_inv, pf.bandwidth, s, zx, zf)
        pf.step(run.odometry[k], run.odometry_cov, run.sightings[k])
        np.testing.assert_array_equal(pf.stream, s)  # the same number of deviates drawn
        np.testing.assert_allclose(pf.particles, ref[0], atol=1e-9)  # m, rad
        np.testing.assert_allclose(pf.weights, ref[1], rtol=1e-9)
        np.testing.assert_allclose(pf.pose, ref[2], atol=1e-9)
        np.testing.assert_allclose(pf.cov, ref[3], rtol=1e-6, atol=1e-15)
        resampled += ref[4]
    assert 5 < resampled < len(run.odometry)  # both branches exercised


def test_predict_and_update_apart_give_the_step() -> None:
    run = simulate_run(seed=4, steps=40)
    a = ParticleLocalisation(run.landmarks, run.truth[0], np.diag([0.01, 0.01, 0.001]), run.sensor_cov, seed=4)
    b = ParticleLocalisation(run.landmarks, run.truth[0], np.diag([0.01, 0.01, 0.001]), run.sensor_cov, seed=4)
    for k in range(40):
        a.step(run.odometry[k], run.odometry_cov, run.sightings[k])
        b.predict(run.odometry[k], run.odometry_cov)
        b.update(run.sightings[k])
        np.testing.assert_array_equal(a.particles, b.particles)
        np.testing.assert_allclose(a.pose, b.pose, atol=1e-12)


def test_the_kernels_angle_wrap_agrees_with_the_geometry_s() -> None:
    from cmdragons.estimation import _kernels as K
    from cmdragons.geometry import wrap_angle

    a = np.concatenate([np.linspace(-40.0, 40.0, 100_001), [-math.pi, math.pi, 0.0, 3 * math.pi, -3 * math.pi]])
    w = np.array([K.wrap(float(x)) for x in a[::97]])
    assert np.all((w >= -math.pi) & (w <= math.pi))
    np.testing.assert_allclose(np.cos(w), np.cos(a[::97]), atol=1e-12)
    np.testing.assert_allclose(w, wrap_angle(a[::97]), atol=1e-12)


@pytest.mark.parametrize("radius", [1.0, 1e-300, 3.7, 1e300])
def test_the_kernels_fast_arctangent_is_within_its_bound_of_atan2(radius: float) -> None:
    from numba import njit

    from cmdragons.estimation import _kernels as K
    from cmdragons.geometry import wrap_angle

    @njit(cache=False)
    def many(y: np.ndarray, x: np.ndarray) -> np.ndarray:
        out = np.empty(y.shape[0])
        for i in range(y.shape[0]):
            out[i] = K.fast_atan2(y[i], x[i])
        return out

    # a dense grid of directions, the axes and the octants' edges among them exactly
    a = np.concatenate([np.linspace(-math.pi, math.pi, 1_000_001), np.arange(-8, 9) * math.pi / 8])
    y, x = radius * np.sin(a), radius * np.cos(a)
    axes = np.array([[0.0, 1.0], [1.0, 0.0], [0.0, -1.0], [-1.0, 0.0], [1.0, 1.0], [-1.0, 1.0], [2.0, -1.0]]) * radius
    y, x = np.concatenate([y, axes[:, 0]]), np.concatenate([x, axes[:, 1]])
    got = many(y, x)
    assert np.all(np.abs(got) <= math.pi)
    assert float(np.max(np.abs(wrap_angle(got - np.arctan2(y, x))))) <= 2e-15  # rad, the docstring's bound
    for yy, xx in [*axes, (0.0, 0.0), (-0.0, -1.0), (-0.0, 1.0)]:  # the zero vector, signed zeros
        assert abs(K.fast_atan2(yy, xx) - math.atan2(yy, xx)) <= 4.5e-16


@pytest.mark.parametrize("kind", ["random", "one", "first_and_last", "sparse"])
def test_the_branch_free_systematic_resampling_picks_as_a_search_of_the_cumulative_weights(kind: str) -> None:
    from cmdragons.estimation import _kernels as K

    rng = np.random.default_rng(7)
    n = 400
    w = {"random": rng.random(n), "one": np.eye(n)[123], "first_and_last": np.eye(n)[0] + np.eye(n)[-1],
         "sparse": rng.random(n) * (rng.random(n) < 0.05)}[kind]
    w = w / w.sum()
    cloud = np.ascontiguousarray(np.vstack([np.arange(n, dtype=np.float64)] * 5))  # each particle's row: its index
    out = np.empty_like(cloud)
    for start in (0.0, 0.37, 0.999999):
        K.resample(cloud, w, start, out)
        expected = np.minimum(np.searchsorted(np.cumsum(w), (start + np.arange(n)) / n), n - 1)
        np.testing.assert_array_equal(out, np.vstack([expected] * 5))


def test_the_kernels_exponential_is_within_an_ulp_of_the_library_s() -> None:
    from cmdragons.estimation import _kernels as K

    x = np.concatenate([np.linspace(-760.0, 760.0, 400_001), [0.0, -708.0, 708.0, -745.2, -1e300, math.log(2) / 2]])
    out = np.empty_like(x)
    K.exps(x, 0.0, out)
    ref = np.array([math.exp(v) if v < math.log(np.finfo(float).max) else math.inf for v in x])
    normal = np.abs(x) <= 708.0
    assert float(np.max(np.abs(out[normal] - ref[normal]) / np.spacing(ref[normal]))) <= 1.0
    np.testing.assert_array_equal(out[~normal], ref[~normal])  # the library's beyond +-708
    shifted = np.empty(5)
    K.exps(np.array([1.0, 2.0, 3.0, 4.0, 5.0]), 5.0, shifted)  # as the reweighing calls it: x - max
    np.testing.assert_allclose(shifted, np.exp(np.arange(-4.0, 1.0)), rtol=2.3e-16)
