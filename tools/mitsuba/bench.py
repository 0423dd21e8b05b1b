#!/usr/bin/env python3
"""vkray against Mitsuba 3 (llvm_ad_rgb) on one scene, paired in one run: K rounds, each a vkray render
and then a Mitsuba render of the same scene at the same image size, samples per pixel and max_depth.

  PY=$(tools/mitsuba/setup | tail -n1)
  $PY tools/mitsuba/bench.py scenes/cornell-path.json [--spp N] [--width W --height H] [--rounds K]
      [--threads T] [--vkray build/vkray] [--device D] [--variant cuda_ad_rgb]

Times are wall times of the rendering alone: vkray's `trace` stage (its render command's log, which
leaves out loading, shader compilation, upload and writing), Mitsuba's mi.render after a warm-up
render that compiles its kernels. Rays per second are not comparable between two path tracers
(Russian roulette and light sampling differ), so the figure of merit is time at equal samples, and
samples (camera paths) per second. Prints one JSON line per render and a summary line.
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vkray_to_mitsuba  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--spp", type=int)
    ap.add_argument("--width", type=int)
    ap.add_argument("--height", type=int)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--threads", type=int, default=os.cpu_count(), help="Mitsuba's threads (default: one per core)")
    ap.add_argument("--vkray", default="build/vkray")
    ap.add_argument("--device", help="vkray's device (default: its choice)")
    ap.add_argument("--variant", default=vkray_to_mitsuba.VARIANT, help="Mitsuba's variant (on an NVIDIA GPU: cuda_ad_rgb)")
    a = ap.parse_args()

    import drjit as dr
    import mitsuba as mi
    mi.set_variant(a.variant)
    mi.set_log_level(mi.LogLevel.Warn)
    dr.set_thread_count(a.threads)
    d, info = vkray_to_mitsuba.scene_dict(a.scene, {"spp": a.spp, "width": a.width, "height": a.height})
    scene = mi.load_dict(d)
    spp, width, height = info["spp"], info["width"], info["height"]
    samples = width * height * spp

    def mitsuba_render(n):
        t0 = time.perf_counter()
        dr.eval(mi.render(scene, spp=n, seed=0))
        dr.sync_thread()
        return time.perf_counter() - t0

    mitsuba_render(spp if spp < 4 else (4 if spp & (spp - 1) == 0 else 5))  # compiles the kernels

    command = [a.vkray, "render", a.scene, "--spp", str(spp), "--width", str(width), "--height", str(height),
               "-o", os.path.join(os.environ.get("TMPDIR", "/tmp"), "vkray-bench-mitsuba.pfm")]
    if a.device:
        command += ["--device", a.device]
    times = {"vkray": [], "mitsuba": []}
    device = ""
    for round_ in range(a.rounds):
        run = subprocess.run(command, capture_output=True, text=True)
        if run.returncode != 0:
            sys.exit(f"bench: {' '.join(command)} exited {run.returncode}:\n{run.stderr}")
        trace = re.search(r"\| trace (\d+(?:\.\d+)?) ms", run.stderr)
        device = (re.search(r"device (.*)", run.stderr) or re.search(r"GPU (.*)", run.stderr) or [None, ""])[1].strip()
        times["vkray"].append(float(trace.group(1)) / 1000.0)
        times["mitsuba"].append(mitsuba_render(spp))
        for who in ("vkray", "mitsuba"):
            print(json.dumps({"round": round_, "renderer": who, "seconds": round(times[who][-1], 4),
                              "samples_per_second": round(samples / times[who][-1])}))
    summary = {"scene": a.scene, "width": width, "height": height, "spp": spp, "integrator": info["integrator"],
               "max_depth": info["max_depth"], "rr_depth": info["rr_depth"], "rounds": a.rounds,
               "vkray_device": device, "mitsuba": f"{mi.__version__} {mi.variant()}, drjit {dr.__version__}, {a.threads} threads"}
    for who in ("vkray", "mitsuba"):
        summary[who + "_seconds_min"] = round(min(times[who]), 4)
        summary[who + "_seconds_median"] = round(statistics.median(times[who]), 4)
        summary[who + "_samples_per_second"] = round(samples / statistics.median(times[who]))
    summary["speed_vkray_over_mitsuba"] = round(statistics.median(times["mitsuba"]) / statistics.median(times["vkray"]), 3)
    print(json.dumps(summary))
    sys.stdout.flush()
    os._exit(0)  # skips drjit's report of the JIT variables mi.render leaves referenced


if __name__ == "__main__":
    main()
