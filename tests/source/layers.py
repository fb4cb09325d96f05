#!/usr/bin/python3
"""The library's folders include one another one way only (docs/development/source-layout.md).

Every folder of include/pegasus/ and src/ sits in one layer below; a file may include the headers of its own
folder and of folders in lower layers, never of its own layer's other folders or of a higher one. So no
folder cycle can form, and the vehicle layer (the aircraft's state, frames, flight log, wind and typed
Vehicle) stays below heli/ and sysid/, which read it. A domain's experiments (its run code: Options -> Result
and the files it writes) live in its `runs/` sub-folder (heli/runs/), which is a layer of its own above the run
framework (runs/); so the engine below never includes a run directory, and runs/ holds only the framework. A new
folder must be placed here: an unplaced folder fails, naming it. Exits 1 with one line per offending include
("FILE:LINE: includes FOLDER/, above it").
"""
import pathlib
import re
import sys

# Lowest first. Within a layer the folders are independent of one another.
LAYERS = [
    ["core"],
    ["random", "io", "parallel"],
    ["models"],
    ["policies", "scenarios", "mdp", "vehicle"],
    ["optimizers", "shaping", "sysid", "logs"],
    ["evaluators"],
    ["envs", "mujoco"],
    ["experiments", "heli"],
    ["codegen"],
    ["runs"],
    ["shaping/runs", "mujoco/runs"],
    ["experiments/runs", "heli/runs", "codegen/runs"],
    ["report", "cli"],
]

# The folder an include names: a domain's experiments are DOMAIN/runs, any other header its top folder.
INCLUDE = re.compile(r'^\s*#\s*include\s+"(?:pegasus/|\.\./)([a-z_]+(?:/runs(?=/))?)/')


def layer_of():
    layers = {}
    for level, folders in enumerate(LAYERS):
        for folder in folders:
            layers[folder] = level
    return layers


def offences(root):
    layers = layer_of()
    found = []
    folders = set()
    for base in (root / "include" / "pegasus", root / "src"):
        for folder in sorted(p for p in base.iterdir() if p.is_dir()):
            runs = folder / "runs"
            names = [folder.name] + ([f"{folder.name}/runs"] if folder.name != "runs" and runs.is_dir() else [])
            for name in names:
                folders.add(name)
                if name not in layers:
                    found.append(f"{(base / name).relative_to(root)}: a folder no layer of tests/source/layers.py holds")
            for path in sorted(folder.rglob("*")):
                if path.suffix not in (".hpp", ".cpp", ".h"):
                    continue
                in_runs = folder.name != "runs" and runs in path.parents
                name = f"{folder.name}/runs" if in_runs else folder.name
                if name not in layers:
                    continue
                for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
                    m = INCLUDE.match(line)
                    if not m or m.group(1) == name:
                        continue
                    target = m.group(1)
                    if target not in layers:
                        found.append(f"{path.relative_to(root)}:{number}: includes {target}/, a folder no layer holds")
                    elif layers[target] >= layers[name]:
                        where = "beside" if layers[target] == layers[name] else "above"
                        found.append(f"{path.relative_to(root)}:{number}: includes {target}/, {where} {name}/")
    return found, folders


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parents[2])
    found, folders = offences(root)
    for line in found:
        print(line)
    if found:
        return 1
    print(f"{len(folders)} folders include one way only, in {len(LAYERS)} layers")
    return 0


if __name__ == "__main__":
    sys.exit(main())
