#!/usr/bin/env python3
"""Resource use of the whole spigpu device (spigpu_top: soc + render core) per profile, yosys 0.23.

    gateware/synth.py [--profile up5k|ecp5] [--json out.json]
up5k: synth_ice40 -dsp (the UP5K has 5,280 LUT4, 30 SB_RAM40_4K, 4 SB_SPRAM256KA, 8 SB_MAC16);
ecp5: synth_ecp5 (LUT4 / TRELLIS_FF / CCU2C / MULT18X18D / DP16KD). Logic synthesis only: placement
and routing are the board flow's (nextpnr), which may merge or split cells. The render core per
stage: gateware/tests/core/synth_core.py.
"""
import argparse, json, os, re, subprocess, sys

GW = os.path.dirname(os.path.abspath(__file__))
PROFILES = {"up5k": ("0", "synth_ice40 -dsp"), "ecp5": ("1", "synth_ecp5")}
CELLS = {
    "lut": ["SB_LUT4", "LUT4"],
    "ff": [r"SB_DFF\w*", "TRELLIS_FF"],
    "carry": ["SB_CARRY", "CCU2C"],
    "dsp": ["SB_MAC16", "MULT18X18D"],
    "bram": ["SB_RAM40_4K", "DP16KD"],
    "spram": ["SB_SPRAM256KA"],
}


def synth(profile):
    value, cmd = PROFILES[profile]
    files = [os.path.join("rtl", "spigpu_top.v")]
    for d in ("soc", "core"):
        files += sorted(os.path.join("rtl", d, f) for f in os.listdir(os.path.join(GW, "rtl", d)) if f.endswith(".v"))
    # the ecp5 profile has no SPRAM: its primitive (known to synth_ice40) is a black box there
    lib = "read_verilog -lib sim/SB_SPRAM256KA.v; " if profile == "ecp5" else ""
    script = (f"{lib}read_verilog -sv -Irtl/soc -Irtl/core {' '.join(files)}; chparam -set PROFILE {value} spigpu_top; "
              f"{cmd} -top spigpu_top; stat")
    out = subprocess.run(["yosys", "-q", "-p", script, "-l", "/dev/stdout"], cwd=GW, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"yosys failed on profile {profile}:\n{out.stderr[-2000:]}")
    sec = out.stdout[out.stdout.rfind("=== spigpu_top ==="):]
    return {k: sum(int(m) for c in names for m in re.findall(rf"\b{c}\s+(\d+)", sec)) for k, names in CELLS.items()}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--profile", choices=sorted(PROFILES), action="append")
    ap.add_argument("--json", help="write the figures as JSON")
    a = ap.parse_args()
    report = {}
    print(f"{'profile':8s} {'LUT4':>6s} {'FF':>6s} {'carry':>6s} {'DSP':>4s} {'BRAM':>5s} {'SPRAM':>5s}")
    for name in a.profile or sorted(PROFILES, reverse=True):
        r = synth(name)
        report[name] = r
        print(f"{name:8s} {r['lut']:6d} {r['ff']:6d} {r['carry']:6d} {r['dsp']:4d} {r['bram']:5d} {r['spram']:5d}", flush=True)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(report, f, indent=2)


if __name__ == "__main__":
    main()
