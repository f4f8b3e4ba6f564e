#!/usr/bin/env python3
"""rtl.cli.bench_fill: `gpubridge --json bench rtl --fill --quick` on both gateware profiles, its
figures checked against physics, not against themselves:

  - every class covers its rectangle exactly (two triangles sharing a diagonal, top-left rule) and
    leaves VRAM (colour, depth buffer, texture) byte for byte as the simulator does with the same
    streams, so no class is fast by drawing wrong;
  - the ecp5 has every class named in REQUIRED (the RGB565 textured ones judge the bilinear goal);
  - 0 < px/clock <= 1 (the rasteriser emits at most a pixel a clock) and
    px/clock <= memory bytes per clock / bytes the memory must move per pixel, where the memory
    moves a 32-bit SPRAM word a clock on the up5k (4 bytes) and one 16-bit SDRAM beat a clock on
    the ecp5 (2 bytes), and a pixel needs at least its colour write, the depth read and write (4 + 4
    bytes) when depth-tested and the destination read when blended (texels may come from the cache:
    not counted);
  - Mpixel/s = px/clock x the profile's core clock;
  - SPI transfer time is not counted: with the boards' SPI clocks divided by 3 (a copy of CONFIGS
    with bridge.spi_clock_hz changed) every class takes the same device clocks within 3 %.

Usage: check_fill_bench.py GPUBRIDGE CONFIGS
"""
import json, os, shutil, subprocess, sys, tempfile

MEMORY_BYTES_PER_CLOCK = {"up5k": 4, "ecp5": 2}
REQUIRED = {"up5k": ["fill RGB565 flat"],
            "ecp5": ["fill RGBA8888 flat", "fill RGB565 flat", "RGBA8888 textured bilinear (64x64 RGBA8888)",
                     "RGB565 textured nearest (64x64 RGBA8888)", "RGB565 textured bilinear (64x64 RGBA8888)"]}
CORE_HZ = {"up5k": 25.125e6, "ecp5": 50e6}  # backends/rtl/src/gateware_profile.cpp


def run(*extra):
    out = subprocess.run([sys.argv[1], "--json", "bench", "rtl", "--fill", "--quick", *extra], check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out)


def slow_spi_configs(tmp):
    """A copy of the configuration directory with every gateware board's SPI clock divided by 3."""
    configs = os.path.join(tmp, "configs")
    shutil.copytree(sys.argv[2], configs)
    for board in ("icebreaker", "ulx3s"):
        path = os.path.join(configs, "boards", board + ".json")
        with open(path) as f:
            profile = json.load(f)
        profile["bridge"]["spi_clock_hz"] //= 3
        with open(path, "w") as f:
            json.dump(profile, f)
    return configs


def main():
    report = run()
    with tempfile.TemporaryDirectory() as tmp:
        slow = run("--config-dir", slow_spi_configs(tmp))
    failures = []
    for profile, mem in MEMORY_BYTES_PER_CLOCK.items():
        rows = report[profile]["rows"]
        if len(rows) < (4 if profile == "up5k" else 12):
            failures.append(f"{profile}: only {len(rows)} scene classes")
        names = [r["name"] for r in rows]
        failures += [f"{profile}: no class {n!r}" for n in REQUIRED[profile] if n not in names]
        for r in rows:
            name = f"{profile} {r['name']}"
            moved = r["bytes_per_pixel"] + (8 if r["depth"] else 0) + (r["bytes_per_pixel"] if r["blend"] else 0)
            bound = min(1.0, mem / moved)
            px = r["px_per_clock"]
            if r["bytes_compared"] < r["width"] * r["height"] * r["bytes_per_pixel"] or r["bytes_differing"]:
                failures.append(f"{name}: {r['bytes_differing']} of {r['bytes_compared']} VRAM bytes differ from the "
                                "simulator's")
            if r["pixels"] != r["width"] * r["height"]:
                failures.append(f"{name}: {r['pixels']} pixels drawn, the rectangle has {r['width'] * r['height']}")
            if not 0 < px <= bound:
                failures.append(f"{name}: {px:.3f} px/clock outside (0, {bound:.3f}] ({mem} memory bytes/clock, "
                                f"{moved} bytes/pixel)")
            if abs(px - r["pixels"] / r["draw_clocks"]) > 1e-9:
                failures.append(f"{name}: px/clock {px} is not pixels / draw clocks")
            if abs(r["mpixel_per_s"] - px * CORE_HZ[profile] / 1e6) > 1e-6:
                failures.append(f"{name}: {r['mpixel_per_s']} Mpixel/s is not px/clock at {CORE_HZ[profile] / 1e6} MHz")
            s = next((x for x in slow[profile]["rows"] if x["name"] == r["name"]), None)
            if s is None or abs(s["draw_clocks"] - r["draw_clocks"]) > 0.03 * r["draw_clocks"]:
                failures.append(f"{name}: {r['draw_clocks']} device clocks, {s and s['draw_clocks']} with the SPI "
                                "clock divided by 3: SPI time is counted")
            print(f"{name:60s} {px:.3f} px/clock (bound {bound:.3f}), {r['mpixel_per_s']:.1f} Mpixel/s, "
                  f"{r['draw_clocks']} clocks ({s and s['draw_clocks']} at a third of the SPI clock)")
    if failures:
        print("\n".join(["FAIL:"] + failures))
        sys.exit(1)
    print("PASS")


if __name__ == "__main__":
    main()
