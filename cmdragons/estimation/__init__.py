"""Estimation examples of the lecture notes (seed 004): the Mars lander's Kalman filter, EKF
localisation, EKF-SLAM and a particle filter, on simulated runs. See docs/estimation.md."""
