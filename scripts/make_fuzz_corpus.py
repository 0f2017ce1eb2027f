#!/usr/bin/env python3
"""Regenerates tests/fuzz/corpus/ (the fuzz targets' seeds) from the examples and tests/data.

Scenes are rewritten so their relative paths resolve from tests/data/scenes (where the
fuzz targets place their input); geometry seeds start with the byte that picks the reader
(fuzz_geometry.cpp). Run from anywhere; it replaces the corpus folders whole.
"""
import json
import pathlib
import shutil

root = pathlib.Path(__file__).resolve().parent.parent
corpus = root / "tests" / "fuzz" / "corpus"


def rewrite_paths(node, scene_dir):
    """Relative file names of an example scene, as seen from tests/data/scenes."""
    if isinstance(node, dict):
        return {k: rewrite_paths(v, scene_dir) for k, v in node.items()}
    if isinstance(node, list):
        return [rewrite_paths(v, scene_dir) for v in node]
    if isinstance(node, str) and node.endswith((".sl", ".obj", ".pts", ".patches")):
        target = (scene_dir / node).resolve().relative_to(root)
        return "../../../" + target.as_posix()
    return node


def fresh(name):
    folder = corpus / name
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True)
    return folder


scenes, renders = fresh("scene"), fresh("render")
for path in sorted(root.glob("examples/*/scene.json")):
    doc = rewrite_paths(json.loads(path.read_text()), path.parent)
    (scenes / f"example_{path.parent.name}.json").write_text(json.dumps(doc, indent=1))
for path in sorted(root.glob("tests/data/scenes/*.json")):
    shutil.copy(path, scenes / path.name)
# Renders are seeded with small scenes, one per geometry type with two lights, an animated
# camera and each example shader: the examples themselves take seconds a run under the
# sanitizers, too slow to fuzz.
geometries = {
    "sphere": {"type": "sphere", "radius": 1},
    "torus": {"type": "torus", "major": 1, "minor": 0.3},
    "plane": {"type": "plane", "size": [3, 2]},
    "bezier": {"type": "bezier", "file": "../../../examples/teapot/teapot.patches"},
    "subdiv": {"type": "subdiv", "file": "../meshes/cube.obj"},
    "loop": {"type": "subdiv", "file": "../meshes/octahedron.obj", "scheme": "loop"},
    "mesh": {"type": "mesh", "file": "../meshes/pentagon.obj"},
    "points": {"type": "points", "file": "../meshes/points.txt"},
}
shader_names = sorted(p.stem for p in root.glob("examples/shaders/*.sl"))
for i, (name, geometry) in enumerate(geometries.items()):
    shader = shader_names[i % len(shader_names)]
    doc = {
        "settings": {"width": 8, "height": 6, "duration": 0.1, "samples_per_pixel": 1},
        "camera": {"keys": [{"t": 0, "eye": [0, 1, 4], "target": [0, 0, 0]},
                            {"t": 1, "eye": [1, 2, 3], "target": [0, 0, 0]}]},
        "lights": [{"type": "ambient", "intensity": 0.2},
                   {"type": "point", "position": [2, 3, 2], "intensity": 10}],
        "shaders": {shader: f"../../../examples/shaders/{shader}.sl"},
        "objects": [{"name": name, "geometry": geometry, "shader": shader,
                     "transform": {"scale": 0.5}}],
    }
    (renders / f"{name}.json").write_text(json.dumps(doc, indent=1))
for path in sorted(root.glob("tests/data/bad_scenes/*.json")):
    shutil.copy(path, scenes / ("bad_" + path.name))

shaders = fresh("shader")
for path in sorted(root.glob("examples/shaders/*.sl")) + sorted(root.glob("tests/data/*shaders/*.sl")):
    shutil.copy(path, shaders / (path.parent.name + "_" + path.name))
# The inputs that once overflowed the stack (issue: reliability), smaller but as deep.
(shaders / "regression_deep_parens.sl").write_text(
    "surface s() { Ci = color(" + "(" * 20000 + "1" + ")" * 20000 + "); }\n")
(shaders / "regression_long_sum.sl").write_text(
    "surface s() { Ci = color(1" + " + 1" * 20000 + "); }\n")

geometry = fresh("geometry")
readers = {".obj": [0, 1, 2], ".patches": [3], ".pts": [4], ".txt": [4]}
sources = sorted(root.glob("examples/**/*.obj")) + sorted(root.glob("examples/**/*.patches")) + \
    sorted(root.glob("examples/**/*.pts")) + sorted(root.glob("tests/data/meshes/*"))
for path in sources:
    for kind in readers.get(path.suffix, []):
        data = bytes([kind]) + path.read_bytes()
        (geometry / f"{kind}_{path.parent.name}_{path.name}").write_bytes(data)
print("corpus:", {p.name: len(list(p.iterdir())) for p in sorted(corpus.iterdir())})
