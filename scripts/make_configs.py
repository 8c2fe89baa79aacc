"""Regenerate the shipped scenario library: configs/{normal,inverse,hotel,kth,office}.yaml and maps/.

Our own buildings, made by `semsearch generate building`, matching the thesis' Table 4.1 (sign
counts and goal doors) and its description of each map's numbering. Run from the repository root:
    python scripts/make_configs.py
"""

from __future__ import annotations

from pathlib import Path

import yaml

import cv2

from semsearch_cli.world.scenario_folder import write_doors
from semsearch_cli.world.buildings.numbered import generate_building
from semsearch_cli.world.buildings.hospital import hospital_image, hospital_scenario, hospital_signs
from semsearch_cli.world.buildings.office import office_image, office_scenario

PLANNERS = [{"name": "greedy"}, {"name": "bvp"}, {"name": "nsos", "alpha": [0.8, 0.9, 1.0]}]

SCHEMA_LINE = "# yaml-language-server: $schema=scenario.schema.json\n"  # editors' completion and checking (semsearch schema)
# name: (layout, numbering, seed, spacing m, signs, goals, floor digit, density delta m^2, description)
LIBRARY = {
    "normal": ("grid", "corridor-parity", 3, 2.7, 113, [54, 55, 111, 124], 2, 4.5,
               "four long corridors around room blocks, each of one parity on both walls (even, odd, even, odd from the "
               "start's), numbers rising from the middle to the ends, as the authors' Normal"),
    "inverse": ("grid", "corridor-parity-in", 3, 2.7, 116, [54, 55, 111, 124], 2, 4.5,
                "the Normal building numbered the other way: rising from the ends of each corridor to its middle"),
    "hotel": ("wings", "odd-even-out", 0, 3.0, 124, [76, 135, 148, 185], 2, 2.5,
              "long corridors with wings and a loop; half the door slots unsigned, so runs of numbers are irregular"),
    "kth": ("angled", "floor", 0, 3.5, 47, [756], 7, 2.5,
            "corridors at 30 and 120 degrees; numbered along each corridor, floor digit 7 first"),
}


# the main job draws its starts (docs/episodes.md); the thesis' fixed start stays in <name>_thesis.yaml
EPISODES = {"hotel": ({"starts": 10, "seed": 0, "min_distance": 10.0}, 1)}  # name: (episodes section, repeats)


def main() -> None:
    root = Path(__file__).resolve().parents[1]
    for name, (lay, scheme, seed, spacing, signs, goals, floor, delta, what) in LIBRARY.items():
        folder = root / "maps" / name
        p = generate_building(lay, scheme, seed, folder, spacing=spacing, signs=signs, goals=goals, name=name,
                              density_delta=delta, planners=PLANNERS, floor=floor)
        scen = yaml.safe_load(p.read_text())
        p.unlink()
        scen["map"]["image"] = f"../maps/{name}/map.png"
        scen["doors"] = f"../maps/{name}/doors.csv"
        header = (SCHEMA_LINE + f"# {name}: {signs} signs, goals {', '.join(map(str, goals))} (as the thesis' Table 4.1); {what}.\n"
                  f"# Our own building: semsearch generate building --layout {lay} --numbering {scheme} --seed {seed} "
                  f"--spacing {spacing} --signs {signs} (floor digit {floor}); regenerate with scripts/make_configs.py.\n")
        if name in EPISODES:
            thesis = {**scen, "name": f"{name}_thesis"}
            (root / "configs" / f"{name}_thesis.yaml").write_text(
                header + f"# The thesis' fixed start, one episode per goal, 10 seeds; configs/{name}.yaml draws its starts.\n"
                + yaml.safe_dump(thesis, sort_keys=False))
            print(f"configs/{name}_thesis.yaml")
            section, repeats = EPISODES[name]
            scen = {k: v for k, v in scen.items() if k != "experiment"}
            scen["episodes"] = section
            scen["experiment"] = {**thesis["experiment"], "seeds": repeats}
            header += (f"# Episodes: {section['starts']} starts drawn per goal (at least {section['min_distance']:g} m from it), "
                       f"{repeats} run each; the thesis' fixed start is configs/{name}_thesis.yaml.\n")
        (root / "configs" / f"{name}.yaml").write_text(header + yaml.safe_dump(scen, sort_keys=False))
        print(f"configs/{name}.yaml")
    (root / "maps" / "office").mkdir(parents=True, exist_ok=True)
    cv2.imwrite(str(root / "maps" / "office" / "map.png"), office_image())
    header = (SCHEMA_LINE + "# office: object search over time (thesis 5.3): 20.5 m x 14.5 m, seven rooms, places A-J,\n"
              "# the mug patterns of Table 5.1, requests at 12:00 and 00:00 (ground truth of Table 5.2),\n"
              "# the combined-patterns run and the moved-mug run. Regenerate with scripts/make_configs.py.\n")
    scen = office_scenario(image="../maps/office/map.png")
    (root / "configs" / "office.yaml").write_text(header + yaml.safe_dump(scen, sort_keys=False, default_flow_style=None))
    print("configs/office.yaml")
    folder = root / "maps" / "hospital"
    folder.mkdir(parents=True, exist_ok=True)
    cv2.imwrite(str(folder / "map.png"), hospital_image())
    write_doors(folder / "doors.csv", hospital_signs())
    header = (SCHEMA_LINE + "# hospital: chained searches (thesis ch. 6): twenty numbered rooms off two crossing corridors,\n"
              "# objects with timelines in rooms 12 and 15, chains of 3-5 stages (door signs, then objects in\n"
              "# the room behind a door). Regenerate with scripts/make_configs.py.\n")
    scen = hospital_scenario(image="../maps/hospital/map.png", doors="../maps/hospital/doors.csv")
    (root / "configs" / "hospital.yaml").write_text(header + yaml.safe_dump(scen, sort_keys=False, default_flow_style=None))
    print("configs/hospital.yaml")


if __name__ == "__main__":
    main()
