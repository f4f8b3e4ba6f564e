#!/usr/bin/env python3
"""Resource use of the render core per stage and in total, for both profiles (yosys 0.23).

Each stage module is synthesised on its own with the parameters the core gives it in that
profile, then the whole core flattened (the total includes what crosses stage boundaries).
    gateware/tests/core/synth_core.py [--profile up5k|ecp5] [--json out.json]
iCE40: LUT4 / FF / SB_CARRY / SB_MAC16 / SB_RAM40_4K; ECP5: LUT4 / FF / CCU2C / MULT18X18D / DP16KD.
"""
import argparse, json, os, re, subprocess, sys, tempfile

RTL = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "rtl", "core")

PROFILES = {
    "up5k": {
        "synth": "synth_ice40 -dsp",
        "top": {"PROFILE": "0", "FEATURES": "8'h3C", "MAX_WIDTH": "320", "MAX_HEIGHT": "240", "VRAM_KIB": "128", "PERF": "0"},
        "stages": [
            ("setup (divider included)", "core_setup_tm", {"IDX_W": "17"}, ["core_setup_prog.v", "core_divider.v"]),
            ("  of which the divider", "core_divider", {"NW": "62", "SKIP": "0"}, []),
            ("rasteriser", "core_raster", {}, []),
            ("attribute steppers", "core_interp_tm", {"RW": "35"}, []),
            ("depth stage", "core_depth", {"PW": "77", "ZLSB": "17", "IDX_W": "17", "AW": "0", "ADDR_W": "17"}, ["core_rdq.v"]),
            ("colour stage", "core_color", {"AW": "0", "IDX_W": "17", "ADDR_W": "17", "FEATURES": "8'h3C"}, ["core_rdq.v"]),
            ("memory port", "core_memport", {"TAGS_AW": "1"}, []),
            ("alias check", "core_alias", {"ADDR_W": "17"}, []),
        ],
    },
    "ecp5": {
        "synth": "synth_ecp5",
        "top": {"PROFILE": "1", "FEATURES": "8'hFF", "MAX_WIDTH": "1024", "MAX_HEIGHT": "768", "VRAM_KIB": "32768", "PERF": "0"},
        "stages": [
            ("setup (dividers included)", "core_setup", {"TEX": "1", "IDX_W": "20", "SKIP": "1", "XREJECT": "1", "NDIV": "3"}, ["core_divider.v"]),
            ("  of which one divider", "core_divider", {"NW": "72", "SKIP": "1"}, []),
            ("rasteriser", "core_raster", {}, []),
            ("one attribute stepper (of 8)", "core_stepper", {"QW": "32"}, []),
            ("depth stage", "core_depth", {"PW": "176", "ZLSB": "20", "IDX_W": "20", "AW": "2", "ADDR_W": "25"}, ["core_rdq.v"]),
            ("texture unit", "core_texture", {"AW": "2", "IDX_W": "20", "ADDR_W": "25"}, ["core_recip_rom.v"]),
            ("colour stage", "core_color", {"AW": "2", "IDX_W": "20", "ADDR_W": "25", "FEATURES": "8'hFF"}, ["core_rdq.v"]),
            ("clear engine", "core_clear", {"ADDR_W": "25"}, []),
            ("memory port", "core_memport", {"TAGS_AW": "3"}, []),
            ("alias check", "core_alias", {"ADDR_W": "25"}, []),
        ],
    },
}

CELLS = {
    "lut": ["SB_LUT4", "LUT4"],
    "carry": ["SB_CARRY", "CCU2C"],
    "dsp": ["SB_MAC16", "MULT18X18D"],
    "bram": ["SB_RAM40_4K", "DP16KD"],
}


def run_yosys(files, top, params, synth):
    chparam = " ".join(f"-set {k} {v}" for k, v in params.items())
    script = f"read_verilog -sv {' '.join(files)}; chparam {chparam} {top}; {synth} -top {top}; stat"
    out = subprocess.run(["yosys", "-q", "-p", script, "-l", "/dev/stdout"], cwd=RTL, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"yosys failed on {top}:\n{out.stderr[-2000:]}")
    text = out.stdout[out.stdout.rfind("Printing statistics"):]
    start = text.find(f"=== {top} ===")
    sec = text[start:] if start >= 0 else text
    end = sec.find("===", len(top) + 8)
    if end > 0:
        sec = sec[:end]
    res = {k: sum(int(m) for c in names for m in re.findall(rf"\b{c}\s+(\d+)", sec)) for k, names in CELLS.items()}
    res["ff"] = sum(int(m) for m in re.findall(r"\b(?:SB_DFF\w*|TRELLIS_FF)\s+(\d+)", sec))
    return res


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--profile", choices=sorted(PROFILES), action="append")
    ap.add_argument("--json", help="write the figures as JSON")
    a = ap.parse_args()
    report = {}
    for name in a.profile or sorted(PROFILES, reverse=True):
        p = PROFILES[name]
        rows = []
        for label, mod, params, extra in p["stages"]:
            rows.append((label, run_yosys([f"{mod}.v"] + extra, mod, params, p["synth"])))
        files = sorted(f for f in os.listdir(RTL) if f.endswith(".v"))
        rows.append(("core, flattened", run_yosys(files, "spigpu_core", p["top"], p["synth"])))
        print(f"\n{name}: {'stage':26s} {'LUT4':>6s} {'FF':>6s} {'carry':>6s} {'DSP':>4s} {'BRAM':>5s}")
        for label, r in rows:
            print(f"{'':6s}{label:26s} {r['lut']:6d} {r['ff']:6d} {r['carry']:6d} {r['dsp']:4d} {r['bram']:5d}")
        report[name] = {label: r for label, r in rows}
    if a.json:
        with open(a.json, "w") as f:
            json.dump(report, f, indent=2)


if __name__ == "__main__":
    main()
