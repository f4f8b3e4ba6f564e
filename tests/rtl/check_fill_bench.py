#!/usr/bin/env python3
"""rtl.cli.bench_fill: `gpubridge --json bench rtl --fill --quick` on both gateware profiles, its
figures checked against physics, not against themselves:

  - every class covers its rectangle exactly (two triangles sharing a diagonal, top-left rule);
  - 0 < px/clock <= 1 (the rasteriser emits at most a pixel a clock) and
    px/clock <= memory bytes per clock / bytes the memory must move per pixel, where the memory
    moves a 32-bit SPRAM word a clock on the up5k (4 bytes) and one 16-bit SDRAM beat a clock on
    the ecp5 (2 bytes), and a pixel needs at least its colour write, the depth read and write (4 + 4
    bytes) when depth-tested and the destination read when blended (texels may come from the cache:
    not counted);
  - Mpixel/s = px/clock x the profile's core clock.

Usage: check_fill_bench.py GPUBRIDGE
"""
import json, subprocess, sys

MEMORY_BYTES_PER_CLOCK = {"up5k": 4, "ecp5": 2}
CORE_HZ = {"up5k": 25.125e6, "ecp5": 50e6}  # backends/rtl/src/gateware_profile.cpp


def main():
    out = subprocess.run([sys.argv[1], "--json", "bench", "rtl", "--fill", "--quick"], check=True,
                         capture_output=True, text=True).stdout
    report = json.loads(out)
    failures = []
    for profile, mem in MEMORY_BYTES_PER_CLOCK.items():
        rows = report[profile]["rows"]
        if len(rows) < (4 if profile == "up5k" else 10):
            failures.append(f"{profile}: only {len(rows)} scene classes")
        for r in rows:
            name = f"{profile} {r['name']}"
            moved = r["bytes_per_pixel"] + (8 if r["depth"] else 0) + (r["bytes_per_pixel"] if r["blend"] else 0)
            bound = min(1.0, mem / moved)
            px = r["px_per_clock"]
            if r["pixels"] != r["width"] * r["height"]:
                failures.append(f"{name}: {r['pixels']} pixels drawn, the rectangle has {r['width'] * r['height']}")
            if not 0 < px <= bound:
                failures.append(f"{name}: {px:.3f} px/clock outside (0, {bound:.3f}] ({mem} memory bytes/clock, "
                                f"{moved} bytes/pixel)")
            if abs(px - r["pixels"] / r["draw_clocks"]) > 1e-9:
                failures.append(f"{name}: px/clock {px} is not pixels / draw clocks")
            if abs(r["mpixel_per_s"] - px * CORE_HZ[profile] / 1e6) > 1e-6:
                failures.append(f"{name}: {r['mpixel_per_s']} Mpixel/s is not px/clock at {CORE_HZ[profile] / 1e6} MHz")
            print(f"{name:60s} {px:.3f} px/clock (bound {bound:.3f}), {r['mpixel_per_s']:.1f} Mpixel/s")
    if failures:
        print("\n".join(["FAIL:"] + failures))
        sys.exit(1)
    print("PASS")


if __name__ == "__main__":
    main()
