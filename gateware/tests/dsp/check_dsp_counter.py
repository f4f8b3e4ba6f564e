#!/usr/bin/env python3
"""dsp_counter (gateware/rtl/soc) simulated with iverilog twice: with yosys's own SB_MAC16 simulation
model (the primitive as synthesis maps it, from yosys's ice40 cells_sim.v) and with the Verilator
model the co-simulation uses (gateware/sim/SB_MAC16.v). Both must equal the logic counters, so the
co-simulation's model behaves as the primitive does for the modes the gateware uses.
    check_dsp_counter.py --yosys YOSYS --iverilog IVERILOG --vvp VVP
"""
import argparse, os, re, subprocess, sys, tempfile

GW = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))


def yosys_mac16(yosys):
    share = os.path.join(os.path.dirname(os.path.dirname(os.path.realpath(yosys))), "share", "yosys", "ice40", "cells_sim.v")
    if not os.path.exists(share):
        sys.exit(f"yosys's ice40 cell models not found at {share}")
    m = re.search(r"^module SB_MAC16\b.*?^endmodule", open(share).read(), re.S | re.M)
    if not m:
        sys.exit(f"no SB_MAC16 in {share}")
    return m.group(0)


def simulate(args, mac_file, tmp, tag):
    out = os.path.join(tmp, re.sub(r"\W", "_", tag))
    srcs = [os.path.join(GW, "tests", "dsp", "dsp_counter_tb.v"), os.path.join(GW, "rtl", "soc", "dsp_counter.v"),
            os.path.join(GW, "rtl", "soc", "dsp_counter_mac.v"), mac_file]
    r = subprocess.run([args.iverilog, "-g2012", "-o", out] + srcs, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"iverilog failed ({tag}):\n{r.stdout}{r.stderr}")
    r = subprocess.run([args.vvp, "-n", out], capture_output=True, text=True)
    m = re.search(r"dsp_counter mismatches=(\d+) final=(\w+)", r.stdout)
    if not m:
        sys.exit(f"no result from the {tag} simulation:\n{r.stdout}{r.stderr}")
    print(f"{tag}: {m.group(0)}")
    if m.group(1) != "0":
        print(r.stdout)
    return m.group(1), m.group(2)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--yosys", default="yosys")
    ap.add_argument("--iverilog", default="iverilog")
    ap.add_argument("--vvp", default="vvp")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        ymac = os.path.join(tmp, "yosys_sb_mac16.v")
        with open(ymac, "w") as f:
            f.write(yosys_mac16(args.yosys) + "\n")
        ours = simulate(args, os.path.join(GW, "sim", "SB_MAC16.v"), tmp, "gateware/sim/SB_MAC16.v")
        theirs = simulate(args, ymac, tmp, "yosys cells_sim.v SB_MAC16")
    if ours[0] != "0" or theirs[0] != "0" or ours != theirs:
        sys.exit("dsp_counter in an SB_MAC16 differs from the logic counters")


if __name__ == "__main__":
    main()
