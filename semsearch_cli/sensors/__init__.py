"""Sensors over the ground-truth world: laser, door cameras, object camera."""

from .doors import DoorCamera, Laser
from .objects import ObjectCamera, PlaceCamera, detect_probability

__all__ = ["DoorCamera", "Laser", "ObjectCamera", "PlaceCamera", "detect_probability"]
