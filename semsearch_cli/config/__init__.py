"""Scenario files (SPEC 1): the shared sections, then one module per kind of search."""

from .base import (BeliefSpec, DoorCameraSpec, DoorSpec, ExperimentSpec, LaserSpec, MapSpec, NavigationSpec,
                   PlannerSpec, RobotSpec, StartSpec, Strict)
from .chain import ChainSpec, StageSpec
from .objects import (CaseSpec, ClassCameraSpec, DetectTable, ObjectCameraSpec, ObjectsSpec, PlaceSpec,
                      RequestSpec)
from .scenario import KINDS, Scenario, load_scenario, parse_scenario, read_yaml, with_param

__all__ = ["BeliefSpec", "CaseSpec", "ChainSpec", "ClassCameraSpec", "DetectTable", "DoorCameraSpec", "DoorSpec",
           "ExperimentSpec", "KINDS", "LaserSpec", "MapSpec", "NavigationSpec", "ObjectCameraSpec", "ObjectsSpec",
           "PlaceSpec", "PlannerSpec", "RequestSpec", "RobotSpec", "Scenario", "StageSpec", "StartSpec", "Strict",
           "load_scenario", "parse_scenario", "read_yaml", "with_param"]
