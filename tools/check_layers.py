#!/usr/bin/env python3
"""The include graph of the project's folders is a DAG (docs/architecture.md, section 2):

  proto <- output, runtime, solid and fluid physics
        <- solid/side, fluid/side (physics, output, runtime), coupler (runtime)
        <- app (coupler, both sides' adapters, and output to check a restart's side files)

Fails, naming the file and the include, if a folder includes a header of a
folder it may not see. Run by ctest (unit.Layers); usage: check_layers.py [ROOT].
"""
import pathlib
import re
import sys

ROOT = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent)

# What each folder may include, besides its own headers.
ALLOWED = {
    "proto": {"proto"},
    "output": {"proto", "output"},
    "runtime": {"proto", "runtime"},
    "solid": {"proto", "solid"},  # the physics: no runtime, no output
    "fluid": {"proto", "fluid"},
    "solid/side": {"proto", "output", "runtime", "solid", "solid/side"},
    "fluid/side": {"proto", "output", "runtime", "fluid", "fluid/side"},
    "solid/app": {"proto", "runtime", "solid", "solid/side"},
    "fluid/app": {"proto", "runtime", "fluid", "fluid/side"},
    "coupler": {"proto", "runtime", "coupler"},
    "app": {"proto", "output", "runtime", "coupler", "solid", "fluid", "solid/side", "fluid/side"},
}


def folder_of_file(path):
    parts = path.relative_to(ROOT).parts
    if parts[0] in ("solid", "fluid") and parts[1] in ("side", "app"):
        return parts[0] + "/" + parts[1]
    return parts[0]


def folder_of_include(name):
    """The folder a quoted include comes from; None for a file's own neighbours."""
    for prefix, folder in (("hfmpm/runtime/", "runtime"), ("hfmpm/coupling/", "coupler"),
                           ("hfmpm/solid/", "solid"), ("hfmpm/fluid/", "fluid"), ("hfmpm/output/", "output"),
                           ("hfmpm/proto/", "proto")):
        if name.startswith(prefix):
            return folder
    if re.fullmatch(r"hfmpm/[a-z_]+\.(hpp|pb\.h)", name):
        return "proto"  # exchange.hpp, time_function.hpp, the generated messages
    if name.endswith("_solid_side.hpp") or name == "solid_scene_rules.hpp":
        return "solid/side"
    if name.endswith("_fluid_side.hpp") or name == "fluid_scene_rules.hpp":
        return "fluid/side"
    return None


problems = []
checked = 0  # includes of the project's headers that were checked
files = 0
for folder in ALLOWED:
    base = ROOT / folder
    if not base.is_dir():
        problems.append(f"{folder}/: missing")
        continue
    for path in sorted(base.rglob("*")):
        if path.suffix not in (".cpp", ".hpp", ".h") or "build" in path.relative_to(ROOT).parts:
            continue
        own = folder_of_file(path)
        if own not in ALLOWED or own != folder:
            continue  # solid/side/... is checked as solid/side, not again as solid
        files += 1
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            # "hfmpm/..." or <hfmpm/...>: either form reaches the same headers
            match = re.match(r'\s*#\s*include\s+(?:"([^"]+)"|<(hfmpm/[^>]+)>)', line)
            if not match:
                continue
            name = match.group(1) or match.group(2)
            included = folder_of_include(name)
            if included is None:
                continue
            checked += 1
            if included not in ALLOWED[own]:
                problems.append(f"{path.relative_to(ROOT)}:{number}: {own}/ includes {name} ({included}/)")

for problem in problems:
    print("layers:", problem)
print(f"layers: {'FAILED' if problems else 'ok'}: {len(problems)} of {checked} includes of project headers "
      f"in {files} files against the folder DAG")
sys.exit(1 if problems else 0)
