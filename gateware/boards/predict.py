#!/usr/bin/env python3
"""The boards' figures and predicted frames per second of every example and scene, from the
scripts/gateware.sh --json reports and the RTL cycle counts (`gpubridge --json bench rtl`).

    gateware/boards/predict.py --report ICEBREAKER.json --report ULX3S.json [--bench BENCH.json]
                               [--fill FILL.json] [--core up5k=CORE_UP5K.json --core ecp5=CORE_ECP5.json]
                               [--doc docs/gateware.md]

--fill takes `gpubridge --json bench rtl --fill`: the whole device's pixels per clock per scene class
(SPI slave, core, memory arbiter, SPRAM or SDRAM co-simulated), turned into fill rates at the board
clocks and checked against the issue's goals (UP5K: >= 25 Mpixel/s untextured; ECP5-85F: >= 50
untextured, >= 25 bilinear-textured). --core takes build/gateware/tests/core/rtl_core_<profile>_bench
--json: the core alone with an ideal memory port, shown beside them (never used for the goals).

A board runs at the clock its PLL makes (iCEBreaker 25.125 MHz; ULX3S 52.083 MHz, its 25 MHz pixel
clock apart: build.py's target_mhz is the core's), provided the routed
design's fmax reaches it: the prediction is cycles / clock, and the report says whether the fmax was
measured (placed and routed) or is still only the target. A design that is not routed but carries a
clock estimate below the target (the ULX3S's `clock_estimate`, gateware/boards/ecp5_timing.py) is
predicted at the estimate. --doc rewrites the blocks between the
"board-figures" (with --report), "fill-rates" (--fill, --core) and "predicted-fps" (--bench) markers
of docs/gateware.md; without it they go to stdout.
"""
import argparse, json, re, sys

BOARD_OF = {"up5k": "icebreaker", "ecp5": "ulx3s"}


def board_clock(report, board):
    r = report.get(board)
    if r is None:
        return None, "no report"
    target = r.get("target_mhz")
    fmax = r.get("fmax_mhz")
    est = r.get("clock_estimate", {}).get("core_mhz")
    if fmax:
        worst = min(fmax.values())
        if worst < target:
            # routed below the PLL's clock: the board is not usable at the target, and at the fmax
            # (a slower PLL setting) it would run this fast at best
            return worst, (f"routed, worst fmax {worst:.2f} MHz, below the {target:g} MHz target: "
                           f"predicted at {worst:.2f} MHz")
        state = f"routed, worst fmax {worst:.2f} MHz"
    elif est and est < target:
        # not routed, and the netlist's estimate does not reach the PLL's clock: predict at the estimate
        ce = r["clock_estimate"]
        return est, (f"synthesised only; the PLL makes {target:g} MHz but the netlist's estimated clock is {est:g} MHz "
                     f"({ce.get('core_mhz_cells_only', 0):g} MHz with no routing at all; docs/gateware.md "
                     f"\"Clock estimate\"): predicted at {est:g} MHz")
    elif "error" in r:
        state = "not routed yet: " + r["error"].split(":", 1)[-1].strip().split(" (")[0]
    else:
        state = "synthesised only, clock not verified by place and route"
    return target, state


def sentence(text):
    return text[:1].upper() + text[1:] + ("" if text.endswith(".") else ".")


def figures(report):
    """The resource and clock figures of each board report, as markdown."""
    lines = []
    ice = report.get("icebreaker")
    if ice:
        u = ice.get("utilisation", {})
        cells = ", ".join(f"{name} {u[k]['used']:,} of {u[k]['available']:,}" for k, name in
                          (("lc", "logic cells"), ("bram", "block RAM"), ("spram", "SPRAM"), ("dsp", "DSP"),
                           ("pll", "PLL"), ("io", "I/O")) if k in u)
        sy = ice.get("synth", {})
        lines.append(f"- **iCEBreaker** ({ice['part']}, target {ice['target_mhz']} MHz): yosys `{sy.get('command', '')}` "
                     f"{sy.get('lut', 0):,} LUT4, {sy.get('ff', 0):,} FF, {sy.get('carry', 0):,} carry; nextpnr-ice40: {cells}.")
        if "lc" in u:
            share = u["lc"]["used"] / u["lc"]["available"]
            lines.append(f"  Goal: at most 90 % of the logic cells ({int(0.9 * u['lc']['available']):,}): "
                         + ("met" if share <= 0.9 else "**missed**") + f" ({100 * share:.0f} %).")
        if ice.get("fmax_mhz"):
            fm = ", ".join(f"`{c}` {f:.2f} MHz" for c, f in ice["fmax_mhz"].items())
            lines.append(f"  Post-route fmax (worst of {len(ice.get('seeds', []))} seed(s)): {fm}.")
        if "error" in ice:
            # the log's path is the build machine's: left out of the document
            lines.append("  **Fails:** " + re.sub(r" \(nextpnr-ice40, log [^;]*; ", " (", ice["error"]))
    ulx = report.get("ulx3s")
    if ulx and "synth" in ulx:
        sy, m, sd = ulx["synth"], ulx["margin_pct"], ulx.get("sdram_ctrl", {})
        lines.append(f"- **ULX3S** ({ulx['part']}, target {ulx['target_mhz']:g} MHz): yosys `synth_ecp5` {sy['lut4']:,} LUT4 + "
                     f"{sy['ccu2c']:,} CCU2C + {sy['dpr16x4']:,} TRELLIS_DPR16X4 = {sy['lut4_equivalent']:,} LUT4 equivalent "
                     f"of 83,640 (margin {m['lut4']} %), {sy['ff']:,} FF (margin {m['ff']} %), {sy['ebr']} EBR of 208 "
                     f"(margin {m['ebr']} %), {sy['dsp']} MULT18X18D of 156 (margin {m['dsp']} %); the SDRAM controller "
                     f"alone {sd.get('lut4', 0):,} LUT4, {sd.get('ccu2c', 0)} CCU2C, {sd.get('ff', 0):,} FF. "
                     + (sentence(ulx.get("pnr", "placed and routed")) if "fmax_mhz" not in ulx else
                        "Post-route fmax: " + ", ".join(f"`{c}` {f:.2f} MHz" for c, f in ulx["fmax_mhz"].items()) + "."))
        ce = ulx.get("clock_estimate")
        if ce and ce.get("core_mhz"):
            cones = "; ".join(f"`{c['from'].replace('u_gpu.', '')}` → `{c['to'].replace('u_gpu.', '')}` {c['ns']} ns "
                              f"({c['levels']} cells)" for c in ce.get("critical", [])[:4])
            lines.append(f"  Clock estimate (`gateware/boards/ecp5_timing.py`: -6 cell delays, {ce['route_ns']:g} ns "
                         f"routing per net, {ce['route_block_ns']:g} ns to a block RAM or multiplier): core "
                         f"**{ce['core_mhz']:g} MHz**, {ce['core_mhz_cells_only']:g} MHz with no routing at all (a bound), "
                         f"pixel {ce.get('pixel_mhz') or 0:g} MHz (needs {ulx.get('pixel_mhz', 25.0):g}), "
                         f"TMDS {ce.get('tmds_mhz') or 0:g} MHz; core target {ulx['target_mhz']:g} MHz: "
                         + ("backed" if ce.get("meets_target") else "**not backed**") + f". Worst cones: {cones}.")
    elif ulx and "error" in ulx:
        lines.append(f"- **ULX3S** fails: {ulx['error']}")
    return "\n".join(lines)


# the issue's fill-rate goals: (profile, scene class, Mpixel/s). The ULX3S goals, untextured and
# bilinear, are judged into an RGB565 buffer, the ULX3S's screen format at 640 x 480: scanning out
# RGBA8888 takes 80 % of the 16-bit SDRAM's clocks on the visible lines, and into RGBA8888 the colour
# writes alone cap any fill at 0.5 px/clock (docs/gateware.md "Performance on the board clocks"); the
# RGBA8888 classes stay in the table. The up5k's is RGB565 too (its 320 x 240 screen formats are
# RGB565 and RGBA2222).
GOALS = [("up5k", "fill RGB565 flat", 25.0), ("ecp5", "fill RGB565 flat", 50.0),
         ("ecp5", "RGB565 textured bilinear (64x64 RGBA8888)", 25.0)]


def px_per_clock(rows, name, key):
    """The px/clock of a scene class in a core bench list (key "value") or a bench rtl --fill list."""
    row = next((r for r in rows or [] if r["name"] == name), None)
    if row is None or not row.get(key):
        return None, None
    return row[key], row


def clock_mhz(report, fill, profile):
    """The board's clock: its report's target, else the profile's core clock the fill bench ran."""
    mhz, _ = board_clock(report, BOARD_OF[profile])
    hz = fill.get(profile, {}).get("core_hz")
    return mhz or (hz / 1e6 if hz else None)


def fill_rates(core, fill, report):
    """Fill rates of every scene class at the board clocks, the whole device's (gpubridge bench rtl
    --fill) beside the core alone's (ideal memory port), and the goals met or missed by the device's."""
    profiles = [p for p in BOARD_OF if p in core or p in fill]
    lines = ["| Scene class | " + " | ".join(f"{BOARD_OF[p]} rectangle | core alone px/clk | device px/clk | "
                                             f"device Mpixel/s" for p in profiles) + " |",
             "|---|" + "---|---|---|---|" * len(profiles)]
    names = []
    for p in profiles:
        names += [r["name"] for r in fill.get(p, {}).get("rows", []) if r["name"] not in names]
        names += [r["name"] for r in core.get(p, []) if r.get("unit") == "px/clk" and r["name"] not in names]
    for name in names:
        cells = []
        for p in profiles:
            mhz = clock_mhz(report, fill, p)
            c, _ = px_per_clock(core.get(p), name, "value")
            d, row = px_per_clock(fill.get(p, {}).get("rows"), name, "px_per_clock")
            cells += [f"{row['width']} × {row['height']}" if row else "—", f"{c:.3f}" if c else "—",
                      f"{d:.3f}" if d else "—", f"{d * mhz:.1f}" if d and mhz else "—"]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    lines.append("")
    for p, name, goal in GOALS:
        mhz = clock_mhz(report, fill, p)
        if not mhz or (p not in core and p not in fill):
            continue
        d, _ = px_per_clock(fill.get(p, {}).get("rows"), name, "px_per_clock")
        c, _ = px_per_clock(core.get(p), name, "value")
        alone = f"; the core alone {c * mhz:.1f}" if c else ""
        if d is None:
            lines.append(f"- goal {BOARD_OF[p]} {name} ≥ {goal:g} Mpixel/s: not judged, no whole-device figure "
                         f"(`gpubridge --json bench rtl --fill`){alone}")
            continue
        rate = d * mhz
        verdict = "met" if rate >= goal else f"**missed**: needs {goal / d:.2f} MHz at this px/clock"
        lines.append(f"- goal {BOARD_OF[p]} {name}: {rate:.1f} Mpixel/s at {mhz:g} MHz ({d:.3f} px/clock, whole device"
                     f"{alone}) against {goal:g}: {verdict}")
    return "\n".join(lines)


def table(bench, report):
    lines = []
    clocks = {}
    for profile, board in BOARD_OF.items():
        mhz, state = board_clock(report, board)
        clocks[profile] = mhz
        if mhz:
            lines.append(f"- {board} ({profile}): {mhz:g} MHz — {state}")
    lines.append("")
    head = "| Scene |"
    rule = "|---|"
    for profile, board in BOARD_OF.items():
        if clocks.get(profile) and profile in bench:
            head += f" {board} cycles | frames/s | Mpixel/s | triangles/s |"
            rule += "---|---|---|---|"
    lines += [head, rule]
    scenes = []
    for profile in BOARD_OF:
        for row in bench.get(profile, {}).get("rows", []):
            if row["scene"] not in scenes:
                scenes.append(row["scene"])
    for scene in scenes:
        line = f"| {scene} |"
        for profile in BOARD_OF:
            if not clocks.get(profile) or profile not in bench:
                continue
            row = next((r for r in bench[profile]["rows"] if r["scene"] == scene), None)
            if row is None:
                line += " — | — | — | — |"
                continue
            fps = clocks[profile] * 1e6 / row["rtl_cycles"]
            line += (f" {row['rtl_cycles']:,.0f} | {fps:,.1f} | {row['pixels'] * fps / 1e6:,.2f} |"
                     f" {row['triangles'] * fps:,.0f} |")
        lines.append(line)
    return "\n".join(lines)


def replace_block(doc, name, text, path):
    begin, end = f"<!-- {name}:begin -->", f"<!-- {name}:end -->"
    if begin not in doc or end not in doc:
        sys.exit(f"predict.py: {path} has no {begin} ... {end} block")
    return re.sub(re.escape(begin) + ".*?" + re.escape(end), lambda _: f"{begin}\n{text}\n{end}", doc, flags=re.S)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--report", action="append", default=[], help="scripts/gateware.sh --json output (repeatable)")
    ap.add_argument("--bench", help="gpubridge --json bench rtl output (the predicted frame rates)")
    ap.add_argument("--core", action="append", default=[], help="PROFILE=FILE: rtl_core_<profile>_bench --json output")
    ap.add_argument("--fill", help="gpubridge --json bench rtl --fill output (the whole device's fill rates)")
    ap.add_argument("--doc", help="rewrite the board-figures, fill-rates and predicted-fps blocks of this markdown file")
    a = ap.parse_args()
    try:
        report = {}
        for path in a.report:
            with open(path) as f:
                report.update(json.load(f))
        core = {}
        for item in a.core:
            profile, _, path = item.partition("=")
            if profile not in BOARD_OF:
                sys.exit(f"predict.py: --core {item}: expected up5k=FILE or ecp5=FILE")
            with open(path) as f:
                core[profile] = json.load(f)
        fill = {}
        if a.fill:
            with open(a.fill) as f:
                fill = json.load(f)
        bench = None
        if a.bench:
            with open(a.bench) as f:
                bench = json.load(f)
    except (OSError, ValueError) as e:
        sys.exit(f"predict.py: {e}")
    blocks = {"board-figures": figures(report)} if report else {}
    if any(v.get("quick") for v in fill.values()) and a.doc:
        sys.exit(f"predict.py: --fill {a.fill} is a --quick run (64 x 48 rectangles); the document takes the full one")
    if core or fill:
        blocks["fill-rates"] = fill_rates(core, fill, report)
    if bench is not None:
        blocks["predicted-fps"] = table(bench, report)
    if not a.doc:
        print("\n\n".join(blocks.values()))
        return
    with open(a.doc) as f:
        doc = f.read()
    for name, text in blocks.items():
        doc = replace_block(doc, name, text, a.doc)
    with open(a.doc, "w") as f:
        f.write(doc)


if __name__ == "__main__":
    main()
