#!/usr/bin/env python3
"""rtl.cli.bench_replay: `gpubridge bench rtl --save-rtl-counters FILE` then `--rtl-counters FILE`
(the gateware's counters replayed beside a fresh simulator run, no co-simulation) on the quick
streams of the ecp5 profile: the replay reports the same RTL cycles, the same simulator counters
and the same predictions as the co-simulated run, and refuses a file without the stream.

Usage: check_bench_replay.py GPUBRIDGE
"""
import json, os, subprocess, sys, tempfile


def bench(*extra):
    out = subprocess.run([sys.argv[1], "--json", "bench", "rtl", "--quick", *extra, "--profile", "ecp5"], check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out)["ecp5"]["rows"]


def main():
    with tempfile.TemporaryDirectory() as tmp:
        saved = os.path.join(tmp, "rtl.json")
        live = bench("--save-rtl-counters", saved)
        replayed = bench("--rtl-counters", saved)
        assert [r["scene"] for r in live] == [r["scene"] for r in replayed], "the same streams"
        assert len(live) == 2, f"two quick streams, got {len(live)}"
        for a, b in zip(live, replayed):
            for key in ("rtl_cycles", "calibrated_cycles", "default_cycles", "counters"):
                assert a[key] == b[key], f"{a['scene']}: {key} differs: {a[key]} vs {b[key]}"
            assert b["simulated_clocks_per_s"] == 0, "a replay co-simulates nothing"
        with open(saved) as f:
            data = json.load(f)
        del data["ecp5"][live[0]["scene"]]
        with open(saved, "w") as f:
            json.dump(data, f)
        r = subprocess.run([sys.argv[1], "bench", "rtl", "--quick", "--rtl-counters", saved, "--profile", "ecp5"],
                           capture_output=True, text=True)
        assert r.returncode != 0 and "holds no" in r.stderr, f"a missing stream is refused: {r.returncode} {r.stderr}"
    print("PASS")


if __name__ == "__main__":
    main()
