#!/usr/bin/env python3
"""Runs the benchmark scenes of shared/bench/SCENES.md through softrast and the llvmpipe
reference (glref) side by side: the same flags, the images compared with imgdiff, samples_passed
against the figures of SCENES.md, and the median frame time of each (the median of RUNS runs'
medians) for each thread count: softrast --threads N beside llvmpipe with LP_NUM_THREADS=N.

usage: compare_scenes.py [--scenes DIR] [--models DIR] [--build DIR] [--out DIR] [--runs N]
                         [--threads 1,2] [--only NAME[,NAME...]] [--all] [--extra "FLAGS"]
By default it runs the rows of the speed issue's table (each with its target ratio) and quad_grid
with mipmaps (no target); --all adds the other SCENES.md cases (flat shading, textured spheres)
and the other real model of ../shared/models (african_head, texture and phong); --extra adds flags
that both renderers take to every run (e.g. --extra "--msaa 4").
Build first with: cmake --preset release -DSOFTRAST_BUILD_REFERENCE=ON && cmake --build --preset
release. Scenes: python3 ../shared/bench/gen_scenes.py DIR (the default DIR is /tmp/scenes).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys

CAMERAS = {
    "spheres_1m": "--eye 0,0,21.73 --target 0,0,0 --up 0,1,0 --fov 45 --near 1 --far 100 "
                  "--cull back --frames 10",
    "overdraw": "--eye 0,0,10 --target 0,0,0 --up 0,1,0 --fov 45 --near 1 --far 100 "
                "--cull back --frames 6",
    "quad_grid": "--eye 0,6,6 --target 0,0,-1 --up 0,1,0 --fov 50 --near 0.5 --far 100 "
                 "--cull back --frames 40",
    # quad_grid with mipmaps: trilinear texturing side by side (issue 6).
    "quad_grid_trilinear": "--eye 0,6,6 --target 0,0,-1 --up 0,1,0 --fov 50 --near 0.5 "
                           "--far 100 --cull back --frames 40 --filter trilinear",
    # A real textured model (../shared/models), as the speed issue measures it.
    "diablo3_pose": "--eye 0,0,3 --target 0,0,0 --up 0,1,0 --fov 45 --near 0.1 --far 100 "
                    "--cull back --frames 40",
    # The other real model of ../shared/models, with the same camera (--all only).
    "african_head": "--eye 0,0,3 --target 0,0,0 --up 0,1,0 --fov 45 --near 0.1 --far 100 "
                    "--cull back --frames 40",
}
# Where each scene's files are: the generated scenes, or the shared models.
MODEL_FILES = {"diablo3_pose": ("diablo3_pose/diablo3_pose.obj",
                                "diablo3_pose/diablo3_pose_diffuse.tga"),
               "african_head": ("african_head/african_head.obj",
                                "african_head/african_head_diffuse.tga")}
# Scenes that are another scene's file drawn with other flags.
SCENE_FILE = {"quad_grid_trilinear": "quad_grid"}
# The speed issue's table: (scene, shader, textured) -> target llvmpipe/softrast ratio.
TARGETS = {
    ("spheres_1m", "gouraud", False): 4, ("spheres_1m", "phong", False): 4,
    ("overdraw", "gouraud", False): 6, ("overdraw", "texture", True): 6,
    ("overdraw", "phong", True): 10, ("quad_grid", "texture", True): 3,
    ("quad_grid", "phong", True): 3, ("diablo3_pose", "phong", True): 4,
}
# Rows run by default besides those, with no target in the issue: trilinear texturing (issue 6
# asked for its speed side by side, not for a ratio).
ALSO_BY_DEFAULT = {("quad_grid_trilinear", "texture", True)}
# (scene, shader, textured) in the order of SCENES.md, then the real model.
CASES = [
    ("spheres_1m", "flat", False), ("spheres_1m", "gouraud", False),
    ("spheres_1m", "phong", False), ("spheres_1m", "texture", True),
    ("overdraw", "flat", False), ("overdraw", "gouraud", False),
    ("overdraw", "texture", True), ("overdraw", "phong", True),
    ("quad_grid", "texture", True), ("quad_grid", "phong", True),
    ("diablo3_pose", "phong", True), ("quad_grid_trilinear", "texture", True),
    ("african_head", "texture", True), ("african_head", "phong", True),
]
# samples_passed that SCENES.md states.
EXPECTED_SAMPLES = {"overdraw": 106166512, "quad_grid": 2073600,
                    "quad_grid_trilinear": 2073600}
THRESHOLD = {"flat": 3, "gouraud": 3, "texture": 8, "phong": 8}


def run_json(command, env):
    result = subprocess.run(command, env=env, capture_output=True, text=True, check=False)
    if result.returncode != 0:
        sys.exit("failed: %s\n%s" % (" ".join(command), result.stderr))
    return json.loads(result.stdout.strip().splitlines()[-1])


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(os.path.dirname(here))
    parser = argparse.ArgumentParser()
    parser.add_argument("--scenes", default="/tmp/scenes")
    parser.add_argument("--build", default=os.path.join(root, "build", "release"))
    parser.add_argument("--out", default="/tmp/compare_scenes")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--threads", default="1,2")
    parser.add_argument("--only", default="")
    parser.add_argument("--models", default=os.path.join(os.path.dirname(root), "shared", "models"))
    parser.add_argument("--all", action="store_true")
    parser.add_argument("--extra", default="")
    args = parser.parse_args()
    softrast = os.path.join(args.build, "softrast")
    glref = os.path.join(args.build, "tools", "reference", "glref")
    imgdiff = os.path.join(args.build, "tools", "reference", "imgdiff")
    threads = [t for t in args.threads.split(",") if t]
    only = set(filter(None, args.only.split(",")))
    os.makedirs(args.out, exist_ok=True)
    rows = []
    for scene, shader, textured in CASES:
        name = "%s_%s" % (scene, shader)
        if only and scene not in only and name not in only:
            continue
        target = TARGETS.get((scene, shader, textured))
        if target is None and not args.all and (scene, shader, textured) not in ALSO_BY_DEFAULT:
            continue
        if scene in MODEL_FILES:
            model, texture = (os.path.join(args.models, f) for f in MODEL_FILES[scene])
        else:
            model = "%s/%s.obj" % (args.scenes, SCENE_FILE.get(scene, scene))
            texture = "%s/checker.png" % args.scenes
        flags = [model, "--size", "1920x1080"]
        flags += CAMERAS[scene].split() + ["--shader", shader, "--light", "0.3,0.5,0.8", "-q"]
        flags += args.extra.split()
        if textured:
            flags += ["--texture", texture]
        soft_png = os.path.join(args.out, name + "_softrast.png")
        gl_png = os.path.join(args.out, name + "_llvmpipe.png")
        env = dict(os.environ)
        soft_ms, gl_ms, samples = {t: [] for t in threads}, {t: [] for t in threads}, None
        peak_mib = 0.0
        for run in range(args.runs):
            for t in threads:
                first = run == 0 and t == threads[0]
                out = ["-o", soft_png] if first else []
                # --maps diffuse: the diffuse map only, as the reference draws it (softrast would
                # otherwise add the normal and specular maps the model's files provide).
                line = run_json([softrast] + flags + ["--maps", "diffuse", "--threads", t] + out,
                                env)
                soft_ms[t].append(line["median_ms"])
                peak_mib = max(peak_mib, line.get("peak_rss_mib", 0.0))
                out = ["-o", gl_png] if first else []
                line = run_json([glref] + flags + out, dict(env, LP_NUM_THREADS=t))
                gl_ms[t].append(line["median_ms"])
                samples = line["samples_passed"]
        diff = run_json([imgdiff, soft_png, gl_png, "--threshold", str(THRESHOLD[shader]),
                         "--diff", os.path.join(args.out, name + "_diff.png")], env)
        row = {"scene": scene, "shader": shader + ("+tex" if textured and shader == "phong" else ""),
               "softrast_ms": {t: statistics.median(v) for t, v in soft_ms.items()},
               "llvmpipe_ms": {t: statistics.median(v) for t, v in gl_ms.items()},
               "samples_passed": samples, "expected_samples": EXPECTED_SAMPLES.get(scene),
               "target": target, "softrast_peak_rss_mib": peak_mib,
               "diff": diff, "softrast_runs": soft_ms, "llvmpipe_runs": gl_ms}
        rows.append(row)
        print(json.dumps(row), flush=True)
    print()
    head = "| scene | shader | " + " | ".join(
        "softrast ms (%s thr) | llvmpipe ms (%s thr) | llvmpipe/softrast (%s thr)" % (t, t, t)
        for t in threads) + \
        " | target | softrast peak MiB | samples_passed (SCENES.md) | differing px | max diff | " \
        "3x3 mismatches | coverage diffs |"
    print(head)
    print("|" + "---|" * (head.count("|") - 1))
    for r in rows:
        d = r["diff"]
        expected = r["expected_samples"]
        print("| %s | %s | %s | %s | %.0f | %d%s | %.4f %% | %d | %d | %d |" % (
            r["scene"], r["shader"],
            " | ".join("%.1f | %.1f | %.2f" % (r["softrast_ms"][t], r["llvmpipe_ms"][t],
                                                r["llvmpipe_ms"][t] / r["softrast_ms"][t])
                       for t in threads),
            (">= %d" % r["target"]) if r["target"] else "-", r["softrast_peak_rss_mib"],
            r["samples_passed"],
            " (%d)" % expected if expected else "", 100 * d["differing_fraction"],
            d["max_channel_diff"], d["mismatches_3x3"], d["coverage_diffs"]))


if __name__ == "__main__":
    main()
