#!/usr/bin/env python3
"""A clock estimate for a synth_ecp5 netlist without nextpnr-ecp5: static timing analysis of the mapped
cells (yosys `write_json`) with the LFE5U -6 speed grade's published cell delays and a fixed routing
allowance per net, since there is no placement to take routing delays from.

    gateware/boards/ecp5_timing.py NETLIST.json [--top ulx3s_top] [--paths 3] [--json OUT]

Cell delays (ps, the "max" column of prjtrellis-db ECP5/timing/cell_timing_6.html, which nextpnr-ecp5
uses): slice flip-flop clock to Q 525; LUT4 236; LUT4 + PFUMX (LUT5) 401, PFUMX select 256, L6MUX21
242 (select 252); CCU2C input to sum 236 (to the upper sum 714), input to carry out 447, carry in to
carry out 71, carry in to sum 474; MULT18X18D without registers A/B to P 3,927, with input registers
clock to P 3,864, with output registers clock to P 735 and A/B setup 3,486; DP16KD without output
register clock to DO 5,830 and address/data/enable setup 340 at most; distributed RAM read address to
data 236, write clock to data 929, write enable setup 392; LSR (synchronous reset) setup 424.

Routing, the unknown without a placement, is charged per net: ROUTE_NS for a net between slices,
ROUTE_BLOCK_NS for a net to or from a block RAM or multiplier (they sit in rows of their own, so their
nets are long), plus FANOUT_NS per sink beyond the first (capped), 0 for a carry chain's own link and
SLICE_NS inside a slice (LUT to its PFUMX). The -6 interconnect table (interconn_timing_6.html) gives
0.1-0.5 ns per programmable switch and a net between neighbouring slices crosses 2-3 of them, so the
allowance is above what nextpnr typically routes a local net in; a net placed across the die (2-3 ns)
on the critical path is what this cannot see. The clock estimate is 1 / (worst path) per clock domain;
paths between clock domains (the TMDS serialiser's synchronised loads) are reported apart and not
counted, as the design samples them a clock after a synchroniser says they are stable.
"""
import argparse, collections, json, sys

ROUTE_NS = 1.0          # a net between slices
ROUTE_BLOCK_NS = 2.0    # a net to or from a DP16KD / MULT18X18D / ALU54B
SLICE_NS = 0.04         # LUT output to the PFUMX / L6MUX21 of its own slice
FANOUT_NS = 0.005       # per sink beyond the first
FANOUT_CAP_NS = 1.0

BLOCKS = {"DP16KD", "MULT18X18D", "ALU54B"}


def lut_arcs(cell):
    return {(i, "Z"): 0.236 for i in "ABCD"}


def ccu2c_arcs(cell):
    a = {}
    for i in "ABCD":
        a[(i + "0", "S0")] = 0.236
        a[(i + "0", "S1")] = 0.714
        a[(i + "1", "S1")] = 0.236
        a[(i + "0", "COUT")] = 0.447
        a[(i + "1", "COUT")] = 0.447
    a[("CIN", "S0")] = 0.474
    a[("CIN", "S1")] = 0.474
    a[("CIN", "COUT")] = 0.071
    return a


def mult_regs(cell):
    p = cell.get("parameters", {})
    def on(name):
        return str(p.get(name, "NONE")).strip() not in ("NONE", "")
    return on("REG_INPUTA_CLK") or on("REG_INPUTB_CLK"), on("REG_OUTPUT_CLK") or on("REG_PIPELINE_CLK")


class Timing:
    """Arrival times over the flattened top module of a yosys JSON netlist."""

    def __init__(self, netlist, top, route_ns=ROUTE_NS, route_block_ns=ROUTE_BLOCK_NS):
        self.route_ns, self.route_block_ns = route_ns, route_block_ns
        mod = netlist["modules"][top]
        self.cells = mod["cells"]
        self.names = {}
        for name, n in mod["netnames"].items():
            for b in n["bits"]:
                if isinstance(b, int) and (b not in self.names or self.names[b].startswith("$")):
                    self.names[b] = name
        self.driver = {}                       # bit -> (cell, port)
        self.sinks = collections.defaultdict(list)
        for cname, c in self.cells.items():
            dirs = c.get("port_directions", {})
            for port, bits in c["connections"].items():
                for i, b in enumerate(bits):
                    if not isinstance(b, int):
                        continue
                    key = port if len(bits) == 1 else f"{port}{i}"
                    if dirs.get(port) == "output":
                        self.driver[b] = (cname, key)
                    else:
                        self.sinks[b].append((cname, key))
        self.unknown = collections.Counter()

    def clock_of(self, cname):
        c = self.cells[cname]
        conn = c["connections"]
        for p in ("CLK", "WCK", "CLKA", "CLKB", "CLK0", "SCLK"):
            if p in conn and isinstance(conn[p][0], int):
                return self.names.get(conn[p][0], str(conn[p][0]))
        return None

    def route(self, bit, sink_cell):
        drv = self.driver.get(bit)
        if drv is None:
            return self.route_ns
        dtype, stype = self.cells[drv[0]]["type"], self.cells[sink_cell]["type"]
        if drv[1] == "COUT" and stype == "CCU2C":
            return 0.0
        if dtype == "LUT4" and stype in ("PFUMX", "L6MUX21"):
            return SLICE_NS
        if dtype == "PFUMX" and stype == "L6MUX21":
            return SLICE_NS
        base = self.route_block_ns if (dtype in BLOCKS or stype in BLOCKS) else self.route_ns
        return base + min(FANOUT_CAP_NS, FANOUT_NS * max(0, len(self.sinks[bit]) - 1))

    def analyse(self):
        """Returns {clock: [(ns, endpoint, path), ...]} worst first, and the cross-domain worst."""
        # combinational arcs of each cell: (input port key, output port key) -> ns
        arcs = {}
        launch = {}                          # output bit -> (clock-to-out ns, clock)
        capture = []                         # (bit, cell, setup ns, clock)
        for cname, c in self.cells.items():
            t, conn = c["type"], c["connections"]
            def bits(port):
                return [b for b in conn.get(port, []) if isinstance(b, int)]
            if t == "LUT4":
                arcs[cname] = lut_arcs(c)
            elif t == "PFUMX":
                arcs[cname] = {("ALUT", "Z"): 0.165, ("BLUT", "Z"): 0.165, ("C0", "Z"): 0.256}
            elif t == "L6MUX21":
                arcs[cname] = {("D0", "Z"): 0.242, ("D1", "Z"): 0.242, ("SD", "Z"): 0.252}
            elif t == "CCU2C":
                arcs[cname] = ccu2c_arcs(c)
            elif t == "TRELLIS_FF":
                clk = self.clock_of(cname)
                for b in bits("Q"):
                    launch[b] = (0.525, clk)
                for p, s in (("DI", 0.0), ("CE", 0.0), ("LSR", 0.424), ("M", 0.0)):
                    for b in bits(p):
                        capture.append((b, cname, s, clk))
            elif t == "TRELLIS_DPR16X4":
                clk = self.clock_of(cname)
                arcs[cname] = {(f"RAD{i}", f"DO{j}"): 0.236 for i in range(4) for j in range(4)}
                for b in bits("DO"):
                    launch[b] = (0.929, clk)      # write clock to read data (the same address)
                for p, s in (("DI", 0.0), ("WAD", 0.0), ("WRE", 0.392)):
                    for b in bits(p):
                        capture.append((b, cname, s, clk))
            elif t == "DP16KD":
                clk = self.clock_of(cname)
                for p in conn:
                    if p.startswith("DO"):
                        for b in bits(p):
                            launch[b] = (5.830, clk)
                    elif p[:2] in ("AD", "DI", "WE", "CE", "CS", "OC") or p.startswith("RST"):
                        for b in bits(p):
                            capture.append((b, cname, 0.340 if not p.startswith("RST") else 0.585, clk))
            elif t == "MULT18X18D":
                reg_in, reg_out = mult_regs(c)
                clk = self.clock_of(cname)
                ins = [p for p in conn if (p[:1] in ("A", "B") and p[1:].isdigit()) or p in ("SIGNEDA", "SIGNEDB")]
                outs = [p for p in conn if p[:1] == "P" and p[1:].isdigit()]
                if reg_out:
                    for p in outs:
                        for b in bits(p):
                            launch[b] = (0.735, clk)
                elif reg_in:
                    for p in outs:
                        for b in bits(p):
                            launch[b] = (3.864, clk)
                if reg_in or reg_out:
                    for p in ins:
                        for b in bits(p):
                            capture.append((b, cname, 0.084 if reg_in else 3.486, clk))
                else:
                    arcs[cname] = {(p, o): 3.927 for p in ins for o in outs}
            elif t in ("EHXPLLL", "ODDRX1F", "IDDRX1F", "$_TBUF_", "TRELLIS_IO", "BB", "IB", "OB"):
                pass                                 # the chip's boundary: I/O timing is not estimated here
            else:
                self.unknown[t] += 1
        # port-key arcs to bit arcs: arrival(bit) = max over driver inputs
        order, arrival, prev = self._topo(arcs, launch)
        results = collections.defaultdict(list)
        cross = []
        for bit, cname, setup, clk in capture:
            if bit not in arrival:
                continue
            a, src_clk = arrival[bit]
            total = a + self.route(bit, cname) + setup
            path = self._path(bit, prev, arrival)
            if src_clk != clk:
                cross.append((total, src_clk, clk, self._label(cname), path))
            else:
                results[clk].append((total, self._label(cname), path))
        for clk in results:
            results[clk].sort(key=lambda x: -x[0])
        cross.sort(key=lambda x: -x[0])
        return results, cross

    def _topo(self, arcs, launch):
        # arrival[bit] = (ns, launching clock); prev[bit] = (input bit, cell) it came through
        arrival = {b: (t, clk) for b, (t, clk) in launch.items()}
        prev = {}
        # dependency graph over bits through combinational cells
        out_of = collections.defaultdict(list)    # input bit -> [(cell, out bit, ns)]
        indeg = collections.Counter()
        for cname, a in arcs.items():
            conn = self.cells[cname]["connections"]
            def bit(key):
                if key in conn:
                    v = conn[key][0]
                else:
                    port = key.rstrip("0123456789")
                    idx = key[len(port):]
                    v = conn.get(port, [None] * (int(idx) + 1 if idx else 1))[int(idx) if idx else 0]
                return v if isinstance(v, int) else None
            for (i, o), ns in a.items():
                bi, bo = bit(i), bit(o)
                if bi is None or bo is None:
                    continue
                out_of[bi].append((cname, bo, ns))
                indeg[bo] += 1
        ready = collections.deque(b for b in set(arrival) | set(out_of) if indeg[b] == 0)
        order = []
        while ready:
            b = ready.popleft()
            order.append(b)
            for cname, bo, ns in out_of.get(b, []):
                if b in arrival:
                    t = arrival[b][0] + self.route(b, cname) + ns
                    if bo not in arrival or t > arrival[bo][0]:
                        arrival[bo] = (t, arrival[b][1])
                        prev[bo] = (b, cname)
                indeg[bo] -= 1
                if indeg[bo] == 0:
                    ready.append(bo)
        loops = sum(1 for v in indeg.values() if v > 0)
        if loops:
            print(f"ecp5_timing: {loops} bits on combinational loops left out", file=sys.stderr)
        return order, arrival, prev

    def _label(self, cname):
        """An endpoint: the register's output net (or the block's name) and its RTL line."""
        c = self.cells[cname]
        q = [b for p in ("Q", "Q0") for b in c["connections"].get(p, []) if isinstance(b, int)]
        name = self.names.get(q[0], cname) if q else cname
        src = c.get("attributes", {}).get("src", "").split("|")[-1]
        return f"{name} ({c['type']}{', ' + src if src else ''})"

    def _path(self, bit, prev, arrival):
        """The path into `bit`, source first: (net, cell type driving it, arrival ns)."""
        steps = []
        while True:
            drv = self.driver.get(bit)
            steps.append((self.names.get(bit, str(bit)), self.cells[drv[0]]["type"] if drv else "input",
                          round(arrival[bit][0], 2)))
            if bit not in prev:
                break
            bit = prev[bit][0]
        return list(reversed(steps))


def stem(name):
    """A register group's name without the bit and the names synthesis derives from it."""
    name = name.split(" (")[0].split("[")[0]
    for cut in ("_LUT4_", "_CCU2C_", "_PFUMX_", "_L6MUX21_", "_TRELLIS_", "_MULT18X18D_", "_DP16KD"):
        if cut in name:
            name = name[:name.index(cut)]
    return name


def report(netlist, top, paths, route_ns=ROUTE_NS, route_block_ns=ROUTE_BLOCK_NS):
    t = Timing(netlist, top, route_ns, route_block_ns)
    results, cross = t.analyse()
    out = {"method": "cell delays of the LFE5U -6 grade (prjtrellis-db) + routing allowance per net",
           "route_ns": route_ns, "route_block_ns": route_block_ns, "fanout_ns": FANOUT_NS, "clocks": {}}
    for clk, rows in results.items():
        worst = rows[0][0]
        out["clocks"][clk] = {"worst_ns": round(worst, 2), "fmax_mhz": round(1000 / worst, 1),
                              "paths": [{"ns": round(ns, 2), "endpoint": ep, "levels": len(p) - 1, "through": p}
                                        for ns, ep, p in rows[:paths]]}
        # the worst path into each distinct endpoint register group, to show more than one cone
        seen, distinct = set(), []
        for ns, ep, p in rows:
            key = stem(ep)
            if key not in seen:
                seen.add(key)
                distinct.append({"ns": round(ns, 2), "from": stem(p[0][0]), "to": key, "endpoint": ep,
                                 "levels": len(p) - 1})
            if len(distinct) == paths:
                break
        out["clocks"][clk]["distinct"] = distinct
    if cross:
        out["cross_domain_worst_ns"] = round(cross[0][0], 2)
    if t.unknown:
        out["unmodelled_cells"] = {k: v for k, v in t.unknown.items() if v}
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("netlist")
    ap.add_argument("--top", default="ulx3s_top")
    ap.add_argument("--paths", type=int, default=3)
    ap.add_argument("--json")
    ap.add_argument("--route-ns", type=float, default=ROUTE_NS, help="routing allowance per net between slices")
    ap.add_argument("--route-block-ns", type=float, default=ROUTE_BLOCK_NS, help="per net to or from a block")
    a = ap.parse_args()
    with open(a.netlist) as f:
        netlist = json.load(f)
    out = report(netlist, a.top, a.paths, a.route_ns, a.route_block_ns)
    for clk, r in out["clocks"].items():
        print(f"{clk}: worst {r['worst_ns']} ns, estimate {r['fmax_mhz']} MHz")
        for p in r["paths"]:
            print(f"  {p['ns']} ns, {p['levels']} cells, into {p['endpoint']}")
            for net, kind, t in p["through"]:
                print(f"    {t:7.2f} {kind:16s} {net[:110]}")
        for d in r["distinct"]:
            print(f"  {d['ns']} ns from {d['from']} into {d['to']} ({d['levels']} cells)")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(out, f, indent=2)


if __name__ == "__main__":
    main()
