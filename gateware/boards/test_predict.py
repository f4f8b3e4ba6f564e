#!/usr/bin/env python3
"""gateware.predict: predict.py judges the fill-rate goals by the whole device's figure
(`bench rtl --fill`), never by the core alone's (ideal memory port), and shows both; at the board's
clock, or at the netlist's estimated clock when that is lower and the design is not routed."""
import os, sys, unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import predict  # noqa: E402
import build  # noqa: E402  (the boards' PLL clocks)

REPORT = {"icebreaker": {"target_mhz": 25.125}, "ulx3s": {"target_mhz": 50}}
CORE = {"ecp5": [{"name": "fill RGBA8888 flat", "value": 0.977, "unit": "px/clk"},
                 {"name": "fill RGB565 flat", "value": 0.978, "unit": "px/clk"},
                 {"name": "RGB565 textured bilinear (64x64 RGBA8888)", "value": 0.690, "unit": "px/clk"}],
        "up5k": [{"name": "fill RGB565 flat", "value": 0.966, "unit": "px/clk"}]}


def fill_row(name, px):
    return {"name": name, "width": 640, "height": 480, "px_per_clock": px}


FILL = {"ecp5": {"rows": [fill_row("fill RGBA8888 flat", 0.45),
                          fill_row("fill RGB565 flat", 0.96),
                          fill_row("RGBA8888 textured bilinear (64x64 RGBA8888)", 0.35),
                          fill_row("RGB565 textured bilinear (64x64 RGBA8888)", 0.55)]},
        "up5k": {"rows": [fill_row("fill RGB565 flat", 0.995)]}}


def goal_line(text, board, name):
    return next(line for line in text.splitlines() if line.startswith(f"- goal {board} {name}"))


class PredictFill(unittest.TestCase):
    def test_goals_use_the_device_figure(self):
        text = predict.fill_rates(CORE, FILL, REPORT)
        flat = goal_line(text, "ulx3s", "fill RGB565 flat")
        # 0.96 px/clock x 50 MHz = 48.0, against 50: missed, although the core alone makes 48.9
        self.assertIn("48.0 Mpixel/s", flat)
        self.assertIn("**missed**", flat)
        self.assertIn("the core alone 48.9", flat)
        bilinear = goal_line(text, "ulx3s", "RGB565 textured bilinear")
        self.assertIn("27.5 Mpixel/s", bilinear)
        self.assertTrue(bilinear.endswith(": met"))
        up5k = goal_line(text, "icebreaker", "fill RGB565 flat")
        self.assertIn("25.0 Mpixel/s", up5k)  # 0.995 x 25.125 = 24.999...
        self.assertIn("**missed**", up5k)

    def test_untextured_goal_is_judged_into_rgb565(self):
        # the RGBA8888 class (0.45 px/clock: 22.5 Mpixel/s, under the 16-bit SDRAM's cap) is shown, not judged
        text = predict.fill_rates(CORE, FILL, REPORT)
        self.assertFalse(any(line.startswith("- goal ulx3s fill RGBA8888 flat") for line in text.splitlines()))
        self.assertIn("| 640 × 480 | 0.977 | 0.450 | 22.5 |", text)

    def test_bilinear_goal_is_judged_into_rgb565(self):
        # the ULX3S's screen format; the RGBA8888 class (0.35 px/clock: 17.5 Mpixel/s) is shown, not judged
        text = predict.fill_rates(CORE, FILL, REPORT)
        self.assertFalse(any(line.startswith("- goal ulx3s RGBA8888 textured bilinear") for line in text.splitlines()))
        self.assertIn("| RGBA8888 textured bilinear (64x64 RGBA8888) | — | — | — | — | 640 × 480 | — | 0.350 | 17.5 |", text)
        self.assertIn("the core alone 34.5", goal_line(text, "ulx3s", "RGB565 textured bilinear"))

    def test_table_shows_both_figures(self):
        text = predict.fill_rates(CORE, FILL, REPORT)
        row = next(line for line in text.splitlines() if line.startswith("| fill RGBA8888 flat |"))
        self.assertIn("| 640 × 480 | 0.977 | 0.450 | 22.5 |", row)

    def test_clock_from_the_fill_report_without_board_reports(self):
        fill = {p: dict(v, core_hz=hz) for (p, v), hz in zip(FILL.items(), (50e6, 25.125e6))}
        text = predict.fill_rates(CORE, fill, {})
        self.assertIn("48.0 Mpixel/s at 50 MHz", goal_line(text, "ulx3s", "fill RGB565 flat"))

    def test_core_alone_never_meets_a_goal(self):
        text = predict.fill_rates(CORE, {}, REPORT)
        flat = goal_line(text, "ulx3s", "RGB565 textured bilinear")
        self.assertIn("not judged", flat)
        self.assertNotIn(": met", text)

    def test_goals_at_the_estimated_clock_when_below_the_target(self):
        report = {"icebreaker": REPORT["icebreaker"],
                  "ulx3s": {"target_mhz": 50, "clock_estimate": {"core_mhz": 20.0, "core_mhz_cells_only": 40.0}}}
        text = predict.fill_rates(CORE, FILL, report)
        # 0.55 px/clock x 20 MHz = 11.0, not the 27.5 the PLL's 50 MHz would give
        bilinear = goal_line(text, "ulx3s", "RGB565 textured bilinear")
        self.assertIn("11.0 Mpixel/s at 20 MHz", bilinear)
        self.assertIn("**missed**", bilinear)
        mhz, state = predict.board_clock(report, "ulx3s")
        self.assertEqual(mhz, 20.0)
        self.assertIn("predicted at 20 MHz", state)

    def test_an_estimate_above_the_target_keeps_the_target(self):
        report = {"ulx3s": {"target_mhz": 50, "clock_estimate": {"core_mhz": 80.0, "core_mhz_cells_only": 120.0}}}
        self.assertEqual(predict.board_clock(report, "ulx3s")[0], 50)

    def test_a_routed_design_below_its_target_is_predicted_at_its_fmax(self):
        slow = {"icebreaker": {"target_mhz": 25.125, "fmax_mhz": {"clk": 16.86}}}
        mhz, state = predict.board_clock(slow, "icebreaker")
        self.assertEqual(mhz, 16.86)
        self.assertIn("predicted at 16.86 MHz", state)
        fast = {"icebreaker": {"target_mhz": 25.125, "fmax_mhz": {"clk": 31.0}}}
        self.assertEqual(predict.board_clock(fast, "icebreaker")[0], 25.125)

    def test_figures_say_whether_the_estimate_backs_the_target(self):
        synth = {"lut4": 1, "ccu2c": 1, "dpr16x4": 1, "lut4_equivalent": 7, "ff": 1, "ebr": 1, "dsp": 1}
        margin = {"lut4": 99.0, "ff": 99.0, "ebr": 99.0, "dsp": 99.0}
        est = {"route_ns": 1.0, "route_block_ns": 2.0, "core_mhz": 20.5, "core_mhz_cells_only": 43.8, "tmds_mhz": 218.1,
               "meets_target": False, "critical": [{"ns": 48.7, "from": "u_gpu.a", "to": "u_gpu.b", "levels": 59}]}
        ulx = {"part": "LFE5U-85F-6BG381C", "target_mhz": 50, "synth": synth, "margin_pct": margin, "clock_estimate": est}
        text = predict.figures({"ulx3s": ulx})
        self.assertIn("core **20.5 MHz**, 43.8 MHz with no routing at all", text)
        self.assertIn("**not backed**", text)
        self.assertIn("`a` → `b` 48.7 ns (59 cells)", text)
        ulx["clock_estimate"] = dict(est, core_mhz=60.0, meets_target=True)
        self.assertIn("core target 50 MHz: backed", predict.figures({"ulx3s": ulx}))

    def test_the_ulx3s_core_clock_is_its_own(self):
        # the ULX3S's core runs on the PLL's 625 / 12 MHz, apart from the 25 MHz pixel clock: a RGB565
        # flat fill of 0.969 px/clock (bench rtl --fill) makes 50.5 Mpixel/s there, 48.5 at the old 50 MHz
        self.assertAlmostEqual(build.ULX3S["target_mhz"], 625 / 12, places=2)
        self.assertEqual(build.ULX3S["pixel_mhz"], 25.0)
        fill = {"ecp5": {"rows": [fill_row("fill RGB565 flat", 0.969)]}}
        report = {"ulx3s": {"target_mhz": build.ULX3S["target_mhz"],
                            "clock_estimate": {"core_mhz": 53.4, "core_mhz_cells_only": 90.0}}}
        line = goal_line(predict.fill_rates({}, fill, report), "ulx3s", "fill RGB565 flat")
        self.assertIn("50.5 Mpixel/s at 52.083 MHz", line)
        self.assertIn(": met", line)
        # an estimate below the new clock still rules
        report["ulx3s"]["clock_estimate"]["core_mhz"] = 46.7
        line = goal_line(predict.fill_rates({}, fill, report), "ulx3s", "fill RGB565 flat")
        self.assertIn("at 46.7 MHz", line)
        self.assertIn("**missed**", line)

    def test_figures_show_the_pixel_clock(self):
        synth = {"lut4": 1, "ccu2c": 1, "dpr16x4": 1, "lut4_equivalent": 7, "ff": 1, "ebr": 1, "dsp": 1}
        margin = {"lut4": 99.0, "ff": 99.0, "ebr": 99.0, "dsp": 99.0}
        est = {"route_ns": 1.0, "route_block_ns": 2.0, "core_mhz": 53.0, "core_mhz_cells_only": 90.0, "tmds_mhz": 218.1,
               "pixel_mhz": 120.0, "meets_target": True, "critical": []}
        ulx = {"part": "LFE5U-85F-6BG381C", "target_mhz": 52.083, "pixel_mhz": 25.0, "synth": synth,
               "margin_pct": margin, "clock_estimate": est}
        self.assertIn("pixel 120 MHz (needs 25)", predict.figures({"ulx3s": ulx}))


if __name__ == "__main__":
    unittest.main()
