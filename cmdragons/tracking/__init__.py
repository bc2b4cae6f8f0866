"""Kalman tracking of the ball and the robots from camera detections (filterpy)."""

from cmdragons.tracking.tracker import Tracker, TrackerParams, TrackerStats

__all__ = ["Tracker", "TrackerParams", "TrackerStats"]
