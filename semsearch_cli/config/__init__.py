"""Scenario files: the shared sections (:mod:`.base`), the common model and the registry of kinds
(:mod:`.scenario`), then one module per kind of search, each declaring its scenario model.
Importing this package registers every kind."""

from .base import (BeliefSpec, DoorCameraSpec, DoorSpec, ExperimentSpec, LaserSpec, MapSpec, NavigationSpec,
                   PlannerSpec, RobotSpec, StartSpec, Strict)
from .scenario import (KINDS, SIGN_SECTIONS, OnMap, Scenario, SignSections, all_fields, kind_of, load_scenario, parse_scenario, read_yaml, register_kind,
                       scenario_schema, with_param)
from .doors import DoorScenario
from .objects import (CaseSpec, ClassCameraSpec, DetectTable, ObjectCameraSpec, ObjectScenario, ObjectsSpec, PlaceSpec,
                      RequestSpec)
from .chain import ChainScenario, ChainSpec, StageSpec
from .indirect import IndirectScenario

__all__ = ["BeliefSpec", "CaseSpec", "ChainScenario", "ChainSpec", "ClassCameraSpec", "DetectTable", "DoorCameraSpec",
           "DoorScenario", "DoorSpec", "ExperimentSpec", "IndirectScenario", "KINDS", "LaserSpec", "MapSpec",
           "NavigationSpec", "ObjectCameraSpec", "ObjectScenario", "ObjectsSpec", "OnMap", "PlaceSpec", "PlannerSpec",
           "RequestSpec", "RobotSpec", "SIGN_SECTIONS", "Scenario", "SignSections", "StageSpec", "StartSpec", "Strict", "all_fields", "kind_of",
           "load_scenario", "parse_scenario", "read_yaml", "register_kind", "scenario_schema", "with_param"]
