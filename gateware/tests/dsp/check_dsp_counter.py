#!/usr/bin/env python3
"""dsp_counter (gateware/rtl/soc) simulated with iverilog three times: with yosys's own SB_MAC16
simulation model (the primitive as synthesis maps it, from yosys's ice40 cells_sim.v), with the
Verilator model the co-simulation uses (gateware/sim/SB_MAC16.v), and as the netlist yosys
`synth_ice40 -dsp` makes of it (the boards' flow: rtl/soc/dsp_counter_mac.v's SB_MAC16_KEPT renamed
back to SB_MAC16), simulated with yosys's models of its cells. All must equal the logic counters:
the co-simulation's model behaves as the primitive does for the modes the gateware uses, and
synthesis keeps the counter (yosys 0.23's ice40_dsp once turned it into an unclocked multiply).
    check_dsp_counter.py --yosys YOSYS --iverilog IVERILOG --vvp VVP
"""
import argparse, os, re, subprocess, sys, tempfile

GW = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))


def yosys_cells(yosys, names):
    """yosys's ice40 simulation models of the named cells (the whole cells_sim.v is not iverilog's)."""
    share = os.path.join(os.path.dirname(os.path.dirname(os.path.realpath(yosys))), "share", "yosys", "ice40", "cells_sim.v")
    if not os.path.exists(share):
        sys.exit(f"yosys's ice40 cell models not found at {share}")
    text, models = open(share).read(), []
    for name in names:
        m = re.search(rf"^module {name}\b.*?^endmodule", text, re.S | re.M)
        if not m:
            sys.exit(f"no {name} in {share}")
        models.append(m.group(0))
    return "\n".join(models) + "\n"


def synthesise(args, tmp):
    """dsp_counter with DSP = 1 (WIDE 0 and 1) through synth_ice40 -dsp as the boards' flow runs it;
    returns the netlists and a testbench whose DSP instances are these netlists."""
    nets = []
    for wide in (0, 1):
        net = os.path.join(tmp, f"dsp_counter_net_w{wide}.v")
        script = (f"read_verilog -sv rtl/soc/dsp_counter.v rtl/soc/dsp_counter_mac.v; "
                  f"chparam -set DSP 1 -set WIDE {wide} dsp_counter; synth_ice40 -dsp -top dsp_counter; "
                  f"chtype -map SB_MAC16_KEPT SB_MAC16; rename dsp_counter dsp_counter_net_w{wide}; "
                  f"write_verilog -noattr {net}")
        r = subprocess.run([args.yosys, "-q", "-p", script], cwd=GW, capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"yosys failed on dsp_counter (WIDE = {wide}):\n{r.stdout}{r.stderr}")
        nets.append(net)
    tb = open(os.path.join(GW, "tests", "dsp", "dsp_counter_tb.v")).read()
    for wide in (0, 1):
        tb, n = re.subn(rf"dsp_counter #\(\.DSP\(1\), \.WIDE\({wide}\)\)", f"dsp_counter_net_w{wide}", tb)
        if n != 1:
            sys.exit(f"dsp_counter_tb.v: expected one DSP instance with WIDE = {wide}, found {n}")
    tb_file = os.path.join(tmp, "dsp_counter_net_tb.v")
    with open(tb_file, "w") as f:
        f.write(tb)
    cells = os.path.join(tmp, "yosys_cells.v")
    with open(cells, "w") as f:
        f.write(yosys_cells(args.yosys, ["SB_LUT4", "SB_CARRY", "SB_DFF", "SB_DFFE", "SB_MAC16"]))
    return [tb_file] + nets + [cells]


def simulate(args, model_files, tmp, tag, tb=None):
    out = os.path.join(tmp, re.sub(r"\W", "_", tag))
    srcs = [tb or os.path.join(GW, "tests", "dsp", "dsp_counter_tb.v"), os.path.join(GW, "rtl", "soc", "dsp_counter.v"),
            os.path.join(GW, "rtl", "soc", "dsp_counter_mac.v")] + model_files
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
            f.write(yosys_cells(args.yosys, ["SB_MAC16"]))
        ours = simulate(args, [os.path.join(GW, "sim", "SB_MAC16.v")], tmp, "gateware/sim/SB_MAC16.v")
        theirs = simulate(args, [ymac], tmp, "yosys cells_sim.v SB_MAC16")
        net = synthesise(args, tmp)
        synthesised = simulate(args, net[1:], tmp, "synth_ice40 -dsp netlist", tb=net[0])
    if ours[0] != "0" or theirs[0] != "0" or ours != theirs:
        sys.exit("dsp_counter in an SB_MAC16 differs from the logic counters")
    if synthesised[0] != "0" or synthesised != ours:
        sys.exit("dsp_counter as synth_ice40 -dsp maps it differs from the logic counters: the SB_MAC16 was not "
                 "kept as instantiated (rtl/soc/dsp_counter_mac.v, the chtype in boards/build.py)")


if __name__ == "__main__":
    main()
