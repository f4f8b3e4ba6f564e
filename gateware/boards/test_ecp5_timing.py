#!/usr/bin/env python3
"""gateware.ecp5_timing: the ULX3S clock estimate adds up the -6 grade's published cell delays and the
routing allowance along the worst register-to-register path of each clock, and keeps paths between
clock domains out of both. Hand-built netlists; the expected sums are written out from the published
figures (prjtrellis-db cell_timing_6.html), not taken from the module."""
import os, sys, unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import ecp5_timing  # noqa: E402

CLK_TO_Q, LUT, CARRY_IN_TO_OUT, A_TO_COUT, CIN_TO_S, MULT = 0.525, 0.236, 0.071, 0.447, 0.474, 3.927
MULT_OUTREG_CLK_TO_P, MULT_OUTREG_SETUP = 0.735, 3.486   # MULT18X18D with its output register


class Netlist:
    def __init__(self):
        self.cells, self.nets, self.next = {}, {}, 10

    def net(self, name):
        if name not in self.nets:
            self.nets[name] = self.next
            self.next += 1
        return self.nets[name]

    def cell(self, name, kind, outputs, inputs, params=None):
        conns = {p: [self.net(n)] for p, n in {**outputs, **inputs}.items()}
        dirs = {**{p: "output" for p in outputs}, **{p: "input" for p in inputs}}
        self.cells[name] = {"type": kind, "parameters": params or {}, "attributes": {},
                            "port_directions": dirs, "connections": conns}

    def ff(self, name, d, q, clk="clk"):
        self.cell(name, "TRELLIS_FF", {"Q": q}, {"DI": d, "CLK": clk})

    def json(self):
        return {"modules": {"top": {"cells": self.cells,
                                    "netnames": {n: {"bits": [b]} for n, b in self.nets.items()}}}}


def worst(netlist, clock="clk", **kw):
    return ecp5_timing.report(netlist.json(), "top", 3, **kw)["clocks"][clock]["worst_ns"]


class Ecp5Timing(unittest.TestCase):
    def test_two_luts_between_registers(self):
        n = Netlist()
        n.ff("a", "d_a", "q_a")
        n.cell("l1", "LUT4", {"Z": "x"}, {"A": "q_a"})
        n.cell("l2", "LUT4", {"Z": "d_b"}, {"B": "x"})
        n.ff("b", "d_b", "q_b")
        # clock to Q, three nets of 1 ns, two LUTs
        self.assertAlmostEqual(worst(n), round(CLK_TO_Q + 3 * 1.0 + 2 * LUT, 2))
        # the bound: no routing at all
        self.assertAlmostEqual(worst(n, route_ns=0.0, route_block_ns=0.0), round(CLK_TO_Q + 2 * LUT, 2))

    def test_carry_chain_link_is_not_routed(self):
        n = Netlist()
        n.ff("a", "d_a", "q_a")
        n.cell("c0", "CCU2C", {"COUT": "co"}, {"A0": "q_a"})
        n.cell("c1", "CCU2C", {"S0": "d_b"}, {"CIN": "co"})
        n.ff("b", "d_b", "q_b")
        self.assertAlmostEqual(worst(n), round(CLK_TO_Q + 1.0 + A_TO_COUT + CIN_TO_S + 1.0, 2))

    def test_unregistered_multiplier_is_combinational(self):
        n = Netlist()
        n.ff("a", "d_a", "q_a")
        n.cell("m", "MULT18X18D", {"P0": "d_b"}, {"A0": "q_a", "CLK0": "clk"},
               {"REG_INPUTA_CLK": "NONE", "REG_INPUTB_CLK": "NONE", "REG_OUTPUT_CLK": "NONE"})
        n.ff("b", "d_b", "q_b")
        # the nets to and from a block take the block allowance (2 ns)
        self.assertAlmostEqual(worst(n), round(CLK_TO_Q + 2.0 + MULT + 2.0, 2))

    def test_multiplier_output_register_splits_the_path(self):
        # a register absorbed into the MULT18X18D (REG_OUTPUT_CLK) ends the path into it and starts
        # the one out of it: FF -> A (setup through the array) and P (clock to out) -> FF
        n = Netlist()
        n.ff("a", "d_a", "q_a")
        n.cell("m", "MULT18X18D", {"P0": "d_b"}, {"A0": "q_a", "CLK0": "clk"},
               {"REG_INPUTA_CLK": "NONE", "REG_INPUTB_CLK": "NONE", "REG_OUTPUT_CLK": "CLK0"})
        n.ff("b", "d_b", "q_b")
        into = round(CLK_TO_Q + 2.0 + MULT_OUTREG_SETUP, 2)
        out_of = round(MULT_OUTREG_CLK_TO_P + 2.0, 2)
        self.assertAlmostEqual(worst(n), max(into, out_of))
        self.assertLess(worst(n), round(CLK_TO_Q + 2.0 + MULT + 2.0, 2))  # shorter than unregistered

    def test_paths_between_clock_domains_are_left_out(self):
        n = Netlist()
        n.ff("a", "d_a", "q_a", clk="clk")
        n.cell("l1", "LUT4", {"Z": "x"}, {"A": "q_a"})
        n.cell("l2", "LUT4", {"Z": "y"}, {"A": "x"})
        n.cell("l3", "LUT4", {"Z": "d_b"}, {"A": "y"})
        n.ff("b", "d_b", "q_b", clk="clk_tmds")        # three LUTs, but into the other domain
        n.cell("l4", "LUT4", {"Z": "d_c"}, {"A": "q_b"})
        n.ff("c", "d_c", "q_c", clk="clk_tmds")
        out = ecp5_timing.report(n.json(), "top", 3)
        self.assertNotIn("clk", out["clocks"])
        self.assertAlmostEqual(out["clocks"]["clk_tmds"]["worst_ns"], round(CLK_TO_Q + 2 * 1.0 + LUT, 2))
        self.assertAlmostEqual(out["cross_domain_worst_ns"], round(CLK_TO_Q + 4 * 1.0 + 3 * LUT, 2))


if __name__ == "__main__":
    unittest.main()
