#!/usr/bin/env python3
"""gateware/boards/sdf_paths.py: the latest arrival at every register input of a routed design, from
nextpnr-ice40's SDF, and clear errors for what is not one. A hand-written SDF in nextpnr's form; the
expected sums are written out from its delays, not taken from the module."""
import os, subprocess, sys, tempfile, unittest

TOOL = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'sdf_paths.py')

# a: register (clock-to-out 500 ps) -> 1000 ps net -> b: LUT (I0 -> O 400) -> 800 ps net -> c: register
# (setup 100): 2,800 ps. a -> 300 ps net -> d: register (setup 100): 900 ps.
SDF = r'''(DELAYFILE
  (SDFVERSION "3.0")
  (DESIGN "top")
  (VENDOR "nextpnr")
  (DIVIDER /)
  (TIMESCALE 1ps)
  (CELL
    (CELLTYPE "top")
    (INSTANCE )
    (DELAY
      (ABSOLUTE
        (INTERCONNECT u_gpu.u_soc.a_SB_DFF_Q_DFFLC/O u_gpu.u_soc.b_SB_LUT4_O_LC/I0 (1000:1000:1000) (1000:1000:1000))
        (INTERCONNECT u_gpu.u_soc.b_SB_LUT4_O_LC/O u_gpu.u_soc.c_SB_DFF_Q_DFFLC/I0 (800:800:800) (800:800:800))
        (INTERCONNECT u_gpu.u_soc.a_SB_DFF_Q_DFFLC/O u_gpu.u_soc.d_SB_DFF_Q_DFFLC/I1 (300:300:300) (300:300:300))
      )
    )
  )
  (CELL
    (CELLTYPE "ICESTORM_LC")
    (INSTANCE u_gpu.u_soc.a_SB_DFF_Q_DFFLC)
    (DELAY (ABSOLUTE (IOPATH (posedge CLK) O (500:500:500) (500:500:500))))
  )
  (CELL
    (CELLTYPE "ICESTORM_LC")
    (INSTANCE u_gpu.u_soc.b_SB_LUT4_O_LC)
    (DELAY (ABSOLUTE (IOPATH I0 O (400:400:400) (400:400:400))))
  )
  (CELL
    (CELLTYPE "ICESTORM_LC")
    (INSTANCE u_gpu.u_soc.c_SB_DFF_Q_DFFLC)
    (TIMINGCHECK (SETUPHOLD I0 (posedge CLK) (100:100:100) (0:0:0)))
  )
  (CELL
    (CELLTYPE "ICESTORM_LC")
    (INSTANCE u_gpu.u_soc.d_SB_DFF_Q_DFFLC)
    (TIMINGCHECK (SETUPHOLD (posedge I1) (posedge CLK) (100:100:100) (0:0:0)))
  )
)
'''


def run(*args):
    return subprocess.run([sys.executable, TOOL, *args], capture_output=True, text=True, timeout=60)


class SdfPaths(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.sdf = os.path.join(self.dir.name, 'r.sdf')
        with open(self.sdf, 'w') as f:
            f.write(SDF)

    def tearDown(self):
        self.dir.cleanup()

    def test_worst_arrival_and_failing_endpoints(self):
        r = run(self.sdf, '5', '--period', '2.0')
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn('# 2 timed endpoints; worst 2.80 ns (357.14 MHz); endpoints over 2.0 ns: 1', r.stdout)
        # the failing endpoint, listed with the registers on its path
        self.assertIn('2.80 u_soc.c_SB_DFF_Q_DFFLC.I0', r.stdout)
        self.assertIn('u_soc.a > u_soc.b > u_soc.c', r.stdout)

    def test_a_longer_period_fails_nothing(self):
        r = run(self.sdf, '--period', '39.8')
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn('endpoints over 39.8 ns: 0', r.stdout)

    def test_full_path_into_an_endpoint(self):
        r = run(self.sdf, '0', '--period', '2.0', '--end', 'c_SB', '--start', 'a_SB')
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn('## path into', r.stdout)
        for arrival in ('0.50', '1.50', '1.90', '2.70'):  # a.O, b.I0, b.O, c.I0 (setup not included)
            self.assertIn(arrival, r.stdout)

    def test_bad_inputs_are_clear_errors(self):
        missing = run(os.path.join(self.dir.name, 'none.sdf'))
        self.assertNotEqual(missing.returncode, 0)
        self.assertIn('cannot read', missing.stderr)
        self.assertIn('--sdf', missing.stderr)
        junk = os.path.join(self.dir.name, 'junk.sdf')
        with open(junk, 'w') as f:
            f.write('(DELAYFILE (CELL (INSTANCE x)')  # unbalanced
        bad = run(junk)
        self.assertNotEqual(bad.returncode, 0)
        self.assertIn('not an SDF file', bad.stderr)
        period = run(self.sdf, '--period', '0')
        self.assertNotEqual(period.returncode, 0)
        self.assertIn('--period', period.stderr)

    def test_help(self):
        r = run('--help')
        self.assertEqual(r.returncode, 0)
        self.assertIn('--period', r.stdout)


if __name__ == '__main__':
    unittest.main()
