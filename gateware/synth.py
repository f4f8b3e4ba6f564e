#!/usr/bin/env python3
"""Resource use of the whole spigpu device (spigpu_top: soc + render core) per profile, yosys 0.23.

    gateware/synth.py [--profile up5k|ecp5] [--modules] [--abc9] [--pack] [--check] [--json out.json]
up5k: synth_ice40 -dsp (the UP5K has 5,280 LUT4, 30 SB_RAM40_4K, 4 SB_SPRAM256KA, 8 SB_MAC16);
ecp5: synth_ecp5 (LUT4 / TRELLIS_FF / CCU2C / MULT18X18D / DP16KD). Logic synthesis only: placement
and routing are the board flow's (nextpnr), which may merge or split cells. The render core per
stage: gateware/tests/core/synth_core.py. --modules keeps the hierarchy (-noflatten) and prints every
module's cells: what each stage costs (the total is then higher than flattened, where yosys optimises
across module boundaries). --abc9 maps the up5k profile with synth_ice40's timing-driven abc9 for the
UltraPlus (-abc9 -device u; fewer LUT4 here, the board flow has to confirm it routes). --check exits 1
when a profile's cells exceed its part (PARTS), naming each resource over. --pack (up5k) also packs the
netlist with nextpnr-ice40 --up5k --package sg48 --pack-only behind a wrapper with the SPI pins, vsync
and one pin folding the frame output: "lc" is then the logic cells the UP5K must hold (a LUT4 and its
flip-flop share one; flip-flops without a LUT of their own and lone carries take one each), and
--check compares those with the 5,280.
"""
import argparse, json, os, re, subprocess, sys, tempfile

GW = os.path.dirname(os.path.abspath(__file__))
PROFILES = {"up5k": ("0", "synth_ice40 -dsp"), "ecp5": ("1", "synth_ecp5")}
# the parts each profile must fit: iCE40 UP5K; ECP5 LFE5U-85F (the ULX3S's)
PARTS = {"up5k": {"lut": 5280, "lc": 5280, "bram": 30, "spram": 4, "dsp": 8},
         "ecp5": {"lut": 83640, "bram": 208, "dsp": 156}}
CELLS = {
    "lut": ["SB_LUT4", "LUT4"],
    "ff": [r"SB_DFF\w*", "TRELLIS_FF"],
    "carry": ["SB_CARRY", "CCU2C"],
    "dsp": ["SB_MAC16", "MULT18X18D"],
    "bram": ["SB_RAM40_4K", "DP16KD"],
    "spram": ["SB_SPRAM256KA"],
}


def count(section):
    return {k: sum(int(m) for c in names for m in re.findall(rf"\b{c}\s+(\d+)", section)) for k, names in CELLS.items()}


PACK_TOP = """module pack_top (input wire clk, input wire rst, input wire spi_sck, input wire spi_cs_n,
  input wire spi_mosi, output wire spi_miso, output wire busy_pin, output reg frame_pin, output wire vsync);
  wire miso, miso_oe, fv, fs, fe, vb; wire [31:0] fw; wire [2:0] fn; wire [1:0] ff; wire [10:0] fwid, fhei;
  assign spi_miso = miso_oe ? miso : 1'bz;
  spigpu_top #(.PROFILE(0)) dut (.clk(clk), .rst(rst), .spi_sck(spi_sck), .spi_cs_n(spi_cs_n), .spi_mosi(spi_mosi),
    .spi_miso(miso), .spi_miso_oe(miso_oe), .busy_pin(busy_pin), .sd_dq_i(16'd0), .vblank(vb), .vsync(vsync),
    .frame_valid(fv), .frame_word(fw), .frame_nbytes(fn), .frame_start(fs), .frame_end(fe), .frame_format(ff),
    .frame_width(fwid), .frame_height(fhei));
  always @(posedge clk) frame_pin <= ^{fv, fw, fn, fs, fe, ff, fwid, fhei, vb};
endmodule
"""


def pack(files, cmd):
    """ICESTORM_LC after nextpnr-ice40 --pack-only of the up5k device behind PACK_TOP."""
    with tempfile.TemporaryDirectory() as tmp:
        top, net = os.path.join(tmp, "pack_top.v"), os.path.join(tmp, "pack.json")
        with open(top, "w") as f:
            f.write(PACK_TOP)
        # dsp_counter_mac's SB_MAC16 passes synth_ice40 under another name (rtl/soc/dsp_counter_mac.v)
        script = (f"read_verilog -sv -Irtl/soc -Irtl/core {' '.join(files)} {top}; {cmd} -top pack_top; "
                  f"chtype -map SB_MAC16_KEPT SB_MAC16; write_json {net}")
        out = subprocess.run(["yosys", "-q", "-p", script], cwd=GW, capture_output=True, text=True)
        if out.returncode != 0:
            sys.exit(f"yosys failed on the pack wrapper:\n{out.stderr[-2000:]}")
        out = subprocess.run(["nextpnr-ice40", "--up5k", "--package", "sg48", "--json", net, "--pack-only"],
                             capture_output=True, text=True)
        m = re.search(r"ICESTORM_LC:\s*(\d+)/", out.stderr + out.stdout)
        if not m:
            sys.exit(f"nextpnr-ice40 --pack-only gave no ICESTORM_LC count:\n{(out.stderr + out.stdout)[-2000:]}")
        return int(m.group(1))


def design_files():
    """The device's sources, relative to gateware/: spigpu_top and every soc and core module."""
    files = [os.path.join("rtl", "spigpu_top.v")]
    for d in ("soc", "core"):
        files += sorted(os.path.join("rtl", d, f) for f in os.listdir(os.path.join(GW, "rtl", d)) if f.endswith(".v"))
    return files


def ice40_blackboxes():
    """A yosys command reading the iCE40 primitives the up5k instantiates (SPRAM, SB_MAC16, SB_LUT4,
    SB_CARRY: their simulation models in sim/) as black boxes, for the ecp5, which has none of them
    (synth_ice40 knows them from its own library)."""
    models = sorted(os.path.join("sim", f) for f in os.listdir(os.path.join(GW, "sim")) if f.startswith("SB_") and f.endswith(".v"))
    return f"read_verilog -lib {' '.join(models)}; "


def synth(profile, modules=False, abc9=False, packed=False):
    value, cmd = PROFILES[profile]
    if abc9 and profile == "up5k":
        cmd += " -abc9 -device u"
    files = design_files()
    lib = ice40_blackboxes() if profile == "ecp5" else ""
    flat = " -noflatten" if modules else ""
    script = (f"{lib}read_verilog -sv -Irtl/soc -Irtl/core {' '.join(files)}; chparam -set PROFILE {value} spigpu_top; "
              f"{cmd}{flat} -top spigpu_top; {'chtype -map SB_MAC16_KEPT SB_MAC16; ' if 'ice40' in cmd else ''}stat")
    out = subprocess.run(["yosys", "-q", "-p", script, "-l", "/dev/stdout"], cwd=GW, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"yosys failed on profile {profile}:\n{out.stderr[-2000:]}")
    if modules:
        return per_module(out.stdout)
    # modules kept as their own (dsp_counter_mac) make stat list the totals under "design hierarchy"
    h = out.stdout.rfind("=== design hierarchy ===")
    res = count(out.stdout[h if h >= 0 else out.stdout.rfind("=== spigpu_top ==="):])
    if packed and profile == "up5k":
        res["lc"] = pack(files, cmd)
    return res


def per_module(log):
    """{module: cells} from a -noflatten stat: each module's last listing in the log (synth_ice40 and
    synth_ecp5 print one of their own), parameter hashes dropped, parameterisations added up."""
    last = {}
    for m in re.finditer(r"^=== (\S+) ===\n(.*?)(?=^=== |\Z)", log, re.S | re.M):
        if m.group(1) != "design":
            last[m.group(1)] = count(m.group(2))
    res = {}
    for full, c in last.items():
        name = re.sub(r"^\$paramod(\$[0-9a-f]+)?\\", "", full).split("\\")[0]
        res[name] = {k: c[k] + res[name][k] for k in c} if name in res else c
    return res


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--profile", choices=sorted(PROFILES), action="append")
    ap.add_argument("--modules", action="store_true", help="per module, hierarchy kept (-noflatten)")
    ap.add_argument("--abc9", action="store_true", help="up5k: synth_ice40 -abc9 -device u")
    ap.add_argument("--pack", action="store_true", help="up5k: logic cells packed by nextpnr-ice40 --pack-only")
    ap.add_argument("--check", action="store_true", help="exit 1 if a profile exceeds its part (flattened figures)")
    ap.add_argument("--json", help="write the figures as JSON")
    a = ap.parse_args()
    report = {}
    head = f"{'LUT4':>6s} {'FF':>6s} {'carry':>6s} {'DSP':>4s} {'BRAM':>5s} {'SPRAM':>5s}"
    row = lambda r: f"{r['lut']:6d} {r['ff']:6d} {r['carry']:6d} {r['dsp']:4d} {r['bram']:5d} {r['spram']:5d}"
    if not a.modules:
        print(f"{'profile':8s} {head}")
    over = []
    for name in a.profile or sorted(PROFILES, reverse=True):
        r = synth(name, a.modules, a.abc9, a.pack)
        report[name] = r
        if a.modules:
            print(f"{name + ' module':24s} {head}")
            for mod, c in sorted(r.items(), key=lambda kv: -kv[1]["lut"]):
                print(f"{mod:24s} {row(c)}")
            total = {k: sum(c[k] for c in r.values()) for k in CELLS}
            print(f"{'total (not flattened)':24s} {row(total)}", flush=True)
        else:
            print(f"{name:8s} {row(r)}" + (f"  logic cells {r['lc']}" if "lc" in r else ""), flush=True)
            over += [f"{name}: {k} {r[k]} > {limit}" for k, limit in PARTS[name].items() if r.get(k, 0) > limit]
    if a.json:
        with open(a.json, "w") as f:
            json.dump(report, f, indent=2)
    if a.check:
        if a.modules:
            sys.exit("--check needs the flattened figures: drop --modules")
        if over:
            sys.exit("does not fit the part: " + "; ".join(over))
        print("fits: " + "; ".join(f"{n} " + ", ".join(f"{k} {report[n][k]}/{v}" for k, v in PARTS[n].items()
                                                      if k in report[n]) for n in report))


if __name__ == "__main__":
    main()
