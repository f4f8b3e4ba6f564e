// What every shell line of README.md and docs/*.md must do when run as written (see
// doc_examples.hpp for the fields, readme_test.cpp for how they run).
//
// Adding a line to a document: add its Step at the same position of that block, saying what it
// must do (run(...).prints(...).leaves(...), daemon(...), viewer(...), alongside(...)), or, if it
// cannot run in a test, skip(line, why) naming where it is covered instead. A line that needs
// hardware runs in its documented no-hardware form: .instead(command, why). Until the document and
// this list agree, the test fails and names the document line.
#include "doc_examples.hpp"

namespace gpubridge::readme {
namespace {

// The default socket under the private XDG_RUNTIME_DIR, as the programs print it.
const std::string kDefaultSocket = R"(unix:[^ ]*/run/gpubridge/gpubridge\.sock)";

// The DMC-1 lines README.md and docs/dmc1.md's quick start both carry.
Step render_mixed_dmc1() {
  return run("build/tools/gpubridge render --device dmc1 tests/dmc1/data/streams/mixed.dmc1 --textures "
             "tests/dmc1/data/textures.bin.gz     --palette tests/dmc1/data/palette.bin --out mixed.png --raw mixed.rgb565 "
             "--timing")
      .prints(R"(rendered .*mixed\.dmc1 \(DMC-1, dmc1 format\): \d+ commands, 1 frame)")
      .prints(R"(wrote mixed\.rgb565: 153600 bytes of RGB565)")
      .prints(R"(timing frame 0: \d+ GPU cycles)")
      .leaves("mixed.png")
      .leaves("mixed.rgb565");
}
Step write_level_dmc1() {
  return run("build/examples/dmc1/gpubridge-dmc1-demo write --frames 64 --out level.dmc1")
      .prints(R"(wrote level\.dmc1: 64 frame\(s\))")
      .leaves("level.dmc1");
}
Step stream_to_dmc1_board() {
  return skip("build/tools/gpubridge render --device dmc1 level.dmc1 --textures tests/dmc1/data/textures.bin.gz     "
              "--palette tests/dmc1/data/palette.bin --board icebreaker-dmc1",
              "needs an iCEBreaker on USB; SerialLink.RenderStreamsToTheBoardThroughItsPort runs it with --tty on a "
              "pseudo-terminal whose other end is the SOC's receiver model");
}
// gpubridged serving the DMC-1 simulator, a golden stream played to it, its next frame taken back.
Step serve_dmc1() {
  return daemon("build/daemon/gpubridged --backend dmc1 &").prints("listening on " + kDefaultSocket).prints("ready");
}
// The DMC-1's frames in a window, and the example client streaming its level live (as fast as 30
// frames/s: 64 frames take over 2 s).
Step view_dmc1() {
  return viewer("build/viewer/gpubridge-view &", {"gpubridge-view - " + kDefaultSocket + R"( - DMC-1 sim - 320x240)"});
}
Step stream_level_dmc1() {
  return run("build/examples/dmc1/gpubridge-dmc1-demo stream")
      .prints(R"(streamed 64 frame\(s\) of the DMC-1 level to )" + kDefaultSocket + R"(: \d+ commands, \d+ bytes in)")
      .within(120);
}
Step play_mixed_dmc1() {
  return alongside("build/tools/gpubridge play tests/dmc1/data/streams/mixed.dmc1 --fps 10 --repeat 30 &")
      .prints(R"(played tests/dmc1/data/streams/mixed\.dmc1: \d+ DMC-1 command words, 30 frames)")
      .within(120);
}
Step screenshot_dmc1() {
  return run("build/tools/gpubridge screenshot --out dmc1-frame.png")
      .prints(R"(frame #\d+ \(320x240, board\) written to dmc1-frame\.png)")
      .leaves("dmc1-frame.png");
}
Step list_dmc1_fields() { return run("build/tools/gpubridge regs --device dmc1").prints(R"(wall +texture +bits +0\.\.9)"); }

std::vector<Example> make() {
  std::vector<Example> all;

  all.push_back({"README.md", "Two commands (fresh Debian 12)", 0, "README_TwoCommands_Demo",
                 {skip("./scripts/demo.sh", "installs Debian packages (root) and rebuilds; its main job runs as "
                                            "CTest demo.headless (scripts/demo-run.sh on this build)")}});
  all.push_back({"README.md", "Two commands (fresh Debian 12)", 1, "README_TwoCommands_Test",
                 {skip("./scripts/test.sh", "is the whole test suite, this test included")}});

  all.push_back({"README.md", "The demo scenes", 0, "README_DemoScenes_OnABoard",
                 {skip("DEMO_BACKEND=emulated:icebreaker ./scripts/demo.sh",
                       "installs Debian packages (root) and rebuilds, like ./scripts/demo.sh; its main job on every "
                       "emulated board profile runs as CTest demo.boards (scripts/demo-run.sh on this build)")}});

  all.push_back({"README.md", "Using it", 0, "README_UsingIt", {
      run("build/tools/gpubridge render examples/scenes/gouraud-triangle.json --out frame.png")
          .prints(R"(1 frame\(s\) scanned out, 1 triangles)")
          .prints(R"(wrote frame\.png: 160x120)")
          .leaves("frame.png"),
      run("build/tools/gpubridge render examples/scenes/gouraud-triangle.json --out frame-4t.png --threads 4")
          .prints(R"(wrote frame-4t\.png: 160x120)")
          .leaves("frame-4t.png"),
      run("build/tools/gpubridge compare frame.png frame-4t.png --tolerance 0 --diff diff.png")
          .prints(R"(match: 0 of 19200 pixels differ)")
          .leaves("diff.png"),
      // The preview rasteriser (issue 24): the run says which accuracy rendered the frame.
      run("build/tools/gpubridge render examples/scenes/gouraud-triangle.json --out preview.png --accuracy preview")
          .prints(R"(accuracy: preview \(the preview rasteriser)")
          .leaves("preview.png"),
      run("build/tools/gpubridge compare frame.png preview.png --tolerance 1").prints(R"(match: \d+ of 19200 pixels differ)"),
      run("build/tools/gpubridge trace convert examples/scenes/gouraud-triangle.json session.gbt")
          .prints(R"(wrote session\.gbt \(binary, \d+ commands)")
          .leaves("session.gbt"),
      run("build/tools/gpubridge trace convert session.gbt session.trace")
          .prints(R"(wrote session\.trace \(text)")
          .leaves("session.trace"),

      daemon("build/daemon/gpubridged --backend sim &").prints("listening on " + kDefaultSocket).prints("ready"),
      run("build/daemon/gpubridged --config configs/gpubridged.json --check-config")
          .prints("configuration OK")
          .prints("effective configuration"),
      run("build/tools/gpubridge status").prints("daemon: +gpubridged .* at " + kDefaultSocket).prints("backend: +sim"),
      // Failed with `bad address "": unknown scheme` before issue 15. It must find the daemon on the
      // default socket and show the frames the next line plays.
      viewer("build/viewer/gpubridge-view &", {"gpubridge-view - " + kDefaultSocket + R"( - .*160x120)"}),
      alongside("build/tools/gpubridge play session.trace --fps 30 --repeat 150 &")
          .prints(R"(played session\.trace: \d+ register writes, 150 swaps)"),
      run("build/tools/gpubridge screenshot --out next-frame.png")
          .prints(R"(frame #\d+ \(160x120, board\) written to next-frame\.png)")
          .leaves("next-frame.png"),
      run("build/tools/gpubridge reg read CAPS").prints(R"(CAPS = 0x[0-9a-f]{16})"),
      // The global --connect before the command (CLI11 refused it before issue 15).
      run("build/tools/gpubridge --connect unix:$XDG_RUNTIME_DIR/gpubridge/gpubridge.sock status")
          .prints("daemon: +gpubridged .* at " + kDefaultSocket),

      run("build/tools/gpubridge boards").prints(R"(icebreaker +spigpu +ft2232h +0403:6010)"),
      // No bridge on a test machine; one that has some lists them.
      run("build/tools/gpubridge probe").prints(R"(No USB-SPI bridges found|0403:|1a86:|04d8:|10c4:)"),
      run("build/tools/gpubridge bringup --board icebreaker")
          .instead("build/tools/gpubridge bringup --board icebreaker --emulate",
                   "no board here: the --emulate form the line's comment gives")
          .prints(R"(register-echo +ok)")
          .prints(R"(scenes +ok)")
          .prints("PASS"),
      run("build/tools/gpubridge bringup --board icebreaker --rtl --mem-bytes 2048 --iterations 1")
          .prints(R"(register-echo +ok)")
          .prints(R"(spi-clock +ok)")
          .prints("PASS"),
      skip("build/tools/gpubridge flash --board icebreaker",
           "needs an iCEBreaker; usb_flash_cli_tests (FlashCli.*) runs it with stand-in programmers on PATH"),
      daemon("build/daemon/gpubridged --backend auto &").warns("auto: no board attached.*using the simulator"),
      run("touch plugged"),
      daemon("build/daemon/gpubridged --backend 'emulated:ft232h-generic?presence=plugged' &"),
      daemon("build/daemon/gpubridged --backend icebreaker --mirror &")
          .instead("build/daemon/gpubridged --backend emulated:icebreaker --mirror",
                   "no board here: the emulated form the line's comment gives"),
      viewer("build/viewer/gpubridge-view --source diff &", {"gpubridge-view - " + kDefaultSocket + R"( - .* - diff)"}),
      // The emulated board's SPI model is slower than the simulator.
      alongside("build/tools/gpubridge play session.trace --fps 30 --repeat 150 &")
          .prints(R"(played session\.trace: .*150 swaps)")
          .within(120),
      run("build/tools/gpubridge screenshot --source sim --out sim.png")
          .prints(R"(frame #\d+ \(160x120, sim\) written to sim\.png)")
          .leaves("sim.png"),

      render_mixed_dmc1(),
      write_level_dmc1(),
      list_dmc1_fields(),
      stream_to_dmc1_board(),
      serve_dmc1(),
      view_dmc1(),
      stream_level_dmc1(),
      play_mixed_dmc1(),
      screenshot_dmc1(),

      skip("build/tools/gpubridge bench accuracy --out-dir docs",
           "rewrites docs/accuracy-report.* and runs for minutes; CTest bench_accuracy_quick_smoke runs it with --quick"),
      skip("build/tools/gpubridge bench accuracy --cordic-only --out-dir docs",
           "rewrites the CORDIC section of docs/accuracy-report.*; CTest bench_accuracy_quick_smoke runs it with --quick "
           "on a copy of a report"),
      skip("build/tools/gpubridge bench dmc1",
           "measures for seconds per stream on a machine shared with the rest of the suite; CTest "
           "dmc1_bench_smoke runs it with one short round"),
      skip("build/tools/gpubridge bench daemon",
           "a 20-second measurement on a machine shared with the rest of the suite; CTest bench_daemon_smoke runs "
           "it with fewer rounds"),
      skip("build/tools/gpubridge bench remote",
           "minutes of paced frame streams on a machine shared with the rest of the suite; CTest bench_remote_smoke "
           "runs it on one example with few frames"),
      run("build/tools/gpubridge bench usb")
          .prints(R"(write-heavy frame: 30000 register writes, payload/SPI clock bits = [\d.]+%)"),
      skip("build/tools/gpubridge bench rtl --quick",
           "co-simulates two examples on both gateware profiles for minutes on a machine shared with the rest of "
           "the suite; CTest rtl.cli.bench_quick runs it"),
      run("build/tools/gpubridge bench rtl --fill --quick")
          .prints(R"(ecp5 \(board ulx3s, 50 MHz\): whole-device fill)")
          .prints(R"(fill RGBA8888 flat +64x48 )")
          .within(300),
      skip("build/bench/protocol/protocol_parser_bench",
           "Google Benchmark runs for minutes (and is built only with libbenchmark)"),
  }});

  // Issue 21: TLS with a pinned fingerprint, the token from the environment, the viewer and the
  // demo pointed at the daemon over tls: (each line in its own shell, so the variables are inline).
  all.push_back({"README.md", "Remote use", 0, "README_RemoteUse", {
      run("echo \"a-long-random-secret\" > token && chmod 600 token").leaves("token"),
      daemon("build/daemon/gpubridged --listen tcp:0.0.0.0:7420 --listen unix: --token-file token &")
          .prints(R"(tls fingerprint SHA256:[0-9a-f]{64})")
          .prints("listening on tcp:0.0.0.0:7420"),
      run("build/daemon/gpubridged --tls-fingerprint").prints(R"(^SHA256:[0-9a-f]{64}\n$)"),
      run("GPUBRIDGE_ADDRESS=tls:127.0.0.1:7420 GPUBRIDGE_TOKEN_FILE=token build/tools/gpubridge status")
          .prints("daemon: +gpubridged .* at tls:127.0.0.1:7420")
          .warns(R"(trusting the daemon at tls:127\.0\.0\.1:7420 on first use: certificate SHA256:[0-9a-f]{64})"),
      viewer("build/viewer/gpubridge-view --connect tls:127.0.0.1:7420 --token \"$(cat token)\" &",
             {R"(gpubridge-view - tls:127\.0\.0\.1:7420)"}),
      run("GPUBRIDGE_ADDRESS=tls:127.0.0.1:7420 GPUBRIDGE_TOKEN_FILE=token build/examples/gpubridge-demo stream "
          "terrain --frames 90")
          .prints(R"(terrain +90 frames in [\d.]+ s)")
          .within(120),
      run("GPUBRIDGE_ADDRESS=tls:127.0.0.1:7420 GPUBRIDGE_TOKEN_FILE=token build/tools/gpubridge play "
          "tests/daemon/data/triangle.trace --fps 30 --repeat 60")
          .prints(R"(played tests/daemon/data/triangle\.trace: \d+ register writes, 60 swaps)")
          .within(120),
  }});

  all.push_back({"README.md", "Testing", 0, "README_Testing", {
      skip("ctest --test-dir build -L daemon", "runs part of this suite (CTest inside CTest)"),
      skip("ctest --test-dir build -L rtl", "runs part of this suite (CTest inside CTest)"),
      skip("scripts/fuzz-smoke.sh 600", "10 minutes per fuzz target, by hand; scripts/test.sh runs the 5-second smoke"),
      skip("scripts/soak-daemon.sh --minutes 10",
           "a 10-minute soak, by hand (docs/daemon.md \"Hostile soak\"); each of its scenarios runs in CTest "
           "daemon_tests (DaemonLimits.*, DaemonIsolation.*, CarelessInput.*)"),
      skip("build/examples/gpubridge-demo goldens --dir examples/golden --write",
           "rewrites the committed goldens; the comparing form runs in docs/examples.md"),
      skip("build/examples/dmc1/gpubridge-dmc1-demo goldens --write",
           "rewrites the committed goldens; CTest dmc1_level_goldens runs the comparing form"),
      skip("build/tools/gpubridge bench accuracy --out-dir docs",
           "rewrites docs/accuracy-report.*; CTest bench_accuracy_quick_smoke runs it with --quick"),
      skip("build/examples/gpubridge-demo figures --dir docs/screenshots",
           "rewrites the committed figures; docs/examples.md's block runs it into another directory"),
  }});

  all.push_back({"docs/gateware.md", "Running the co-simulation", 0, "docs_gateware_Running", {
      run("build/tools/gpubridge bringup --board icebreaker --rtl --mem-bytes 2048 --iterations 1")
          .prints(R"(register-echo +ok)")
          .prints("PASS"),
      skip("build/daemon/gpubridged --backend rtl:icebreaker --mirror &",
           "CTest daemon_mirror_tests (*Gateware*) runs it through the FT2232H driver and checks every frame"),
      skip("build/tools/gpubridge bench rtl --quick", "minutes of co-simulation; CTest rtl.cli.bench_quick runs it"),
      skip("build/tools/gpubridge bench rtl --fit", "the full calibration run, an hour of co-simulation, by hand"),
      skip("build/tools/gpubridge bench rtl --fill",
           "framebuffer-sized rectangles, minutes of co-simulation; CTest rtl.cli.bench_fill runs the --quick form"),
      skip("gateware/synth.py --pack --check", "yosys synthesis of both profiles and nextpnr packing take many minutes, by hand"),
      skip("gateware/tests/core/synth_core.py", "yosys synthesis per stage takes many minutes, by hand"),
      skip("build/gateware/tests/core/rtl_core_ecp5_bench", "a measurement, by hand; the core's tests run in ctest -L rtl"),
  }});

  all.push_back({"docs/gateware.md", "Building the bitstreams", 0, "docs_gateware_BuildingTheBitstreams", {
      skip("scripts/gateware.sh --board icebreaker --seeds 4 --json build/gateware/boards/icebreaker-report.json",
           "yosys and four place-and-route runs take many minutes; CTest gateware.icebreaker.pnr runs it with one seed "
           "(on unless -DGPUBRIDGE_GATEWARE_PNR=OFF)"),
      skip("scripts/gateware.sh --board ulx3s --json build/gateware/boards/ulx3s-report.json",
           "minutes of yosys synth_ecp5; CTest gateware.ulx3s.synth runs it"),
      skip("gateware/boards/predict.py --report build/gateware/boards/icebreaker-report.json --report "
           "build/gateware/boards/ulx3s-report.json --bench bench-rtl.json --fill fill.json --core up5k=core-up5k.json "
           "--core ecp5=core-ecp5.json --doc docs/gateware.md",
           "rewrites docs/gateware.md from reports that take an hour of synthesis and co-simulation, by hand"),
  }});
  all.push_back({"docs/gateware.md", "Building the bitstreams", 1, "docs_gateware_BuildingTheBitstreamsEcp5", {
      skip("nextpnr-ecp5 --85k --package CABGA381 --speed 6 --lpf gateware/boards/ulx3s/ulx3s.lpf --freq 52.083 --json "
           "build/gateware/boards/ulx3s.json --textcfg build/gateware/boards/ulx3s.config --report "
           "build/gateware/boards/ulx3s-pnr.json",
           "nextpnr-ecp5 is not in Debian 12; scripts/gateware.sh runs it when it is on PATH"),
      skip("ecppack --compress build/gateware/boards/ulx3s.config build/gateware/boards/ulx3s.bit",
           "ecppack is not in Debian 12; scripts/gateware.sh runs it when it is on PATH"),
  }});
  all.push_back({"docs/gateware.md", "Building the bitstreams", 2, "docs_gateware_FlowOptions", {
      skip("nextpnr-ice40 --up5k --package sg48 --pcf gateware/boards/icebreaker/icebreaker.pcf --freq 25.125 --json "
           "build/gateware/boards/icebreaker.json --seed N --report r.json --timing-allow-fail OPTION",
           "a template (a seed N and an option OPTION per run of the sweep), minutes of place and route each; "
           "CTest gateware.icebreaker.pnr runs the board flow's own command"),
  }});
  all.push_back({"docs/gateware.md", "Building the bitstreams", 3, "docs_gateware_FlowOptions88", {
      skip("nextpnr-ice40 --up5k --package sg48 --pcf gateware/boards/icebreaker/icebreaker.pcf --freq 25.125 --json "
           "build/gateware/boards/icebreaker.json --seed N --timing-allow-fail --report rN.json OPTION",
           "a template (a seed N and an option OPTION per run of the fmax-pnr2 sweep), minutes of place and route each; "
           "CTest gateware.icebreaker.pnr runs the board flow's own command"),
  }});
  all.push_back({"docs/gateware.md", "Clock estimate (ULX3S, without nextpnr-ecp5)", 0, "docs_gateware_ClockEstimate", {
      skip("scripts/gateware.sh --board ulx3s --json build/gateware/boards/ulx3s-report.json",
           "minutes of yosys synth_ecp5; CTest gateware.ulx3s.synth runs it"),
      skip("gateware/boards/ecp5_timing.py build/gateware/boards/ulx3s.json --paths 5",
           "needs the netlist the line before writes; CTest rtl.predict.ecp5_timing tests the module"),
      skip("gateware/boards/ecp5_timing.py build/gateware/boards/ulx3s.json --route-ns 0 --route-block-ns 0",
           "needs the netlist the line before writes; CTest rtl.predict.ecp5_timing tests the module"),
  }});

  all.push_back({"docs/dmc1.md", "Quick start", 0, "docs_dmc1_QuickStart", {
      render_mixed_dmc1(),
      run("cmp mixed.rgb565 tests/dmc1/data/golden/mixed.rgb565"),
      write_level_dmc1(),
      run("build/tools/gpubridge render --device dmc1 level.dmc1 --textures tests/dmc1/data/textures.bin.gz     "
          "--palette tests/dmc1/data/palette.bin --frames-dir level-frames")
          .prints(R"(64 frame\(s\))")
          .leaves("level-frames/frame-00063.png")
          .within(120),
      skip("build/tools/gpubridge bench dmc1",
           "measures for seconds per stream; CTest dmc1_bench_smoke runs it with one short round"),
      list_dmc1_fields(),
  }});

  all.push_back({"docs/dmc1.md", "Behind the daemon", 0, "docs_dmc1_BehindTheDaemon", {
      serve_dmc1(),
      play_mixed_dmc1(),
      screenshot_dmc1(),
      run("build/tools/gpubridge status").prints("device: +DMC-1").prints("backend: +sim"),
      skip("build/daemon/gpubridged --backend icebreaker-dmc1 &",
           "needs an iCEBreaker on USB; DaemonDmc1.BoardBackendStreamsToItsPortAndShowsTheSimulatorsFrames serves a "
           "board profile whose port is a pseudo-terminal, the SOC's receiver model on its other end"),
  }});

  all.push_back({"docs/dmc1.md", "Example client", 0, "docs_dmc1_ExampleClientLive", {
      serve_dmc1(),
      view_dmc1(),
      stream_level_dmc1(),
      run("build/examples/dmc1/gpubridge-dmc1-demo stream --fps 0 --frames 256 --json")
          .prints(R"("frames": 256)")
          .prints(R"("commands": \d+)")
          .prints(R"("interrupted": false)")
          .within(120),
  }});

  all.push_back({"docs/dmc1.md", "Board path", 0, "docs_dmc1_BoardPath", {
      run("build/tools/gpubridge boards").prints(R"(icebreaker-dmc1 +dmc1 +uart +0403:6010)"),
      skip("build/tools/gpubridge flash --board icebreaker-dmc1 soc.bin",
           "needs an iCEBreaker and the SOC's bitstream; FlashCli.BoardsWithoutARecipeOrWithForeignBitstreamsSayWhatToDo "
           "runs it with a stand-in programmer"),
      skip("build/tools/gpubridge probe --board icebreaker-dmc1",
           "needs the board; without one it exits 1 naming the USB ids it looked for (CTest dmc1_cli_probe_uart_board)"),
      skip("build/tools/gpubridge render --device dmc1 level.dmc1 --textures tests/dmc1/data/textures.bin.gz     "
           "--palette tests/dmc1/data/palette.bin --out level.png --board icebreaker-dmc1",
           "needs an iCEBreaker on USB; SerialLink.RenderStreamsToTheBoardThroughItsPort runs it with --tty on a "
           "pseudo-terminal whose other end is the SOC's receiver model"),
  }});

  all.push_back({"docs/boards.md", "Flashing", 0, "docs_boards_Flashing", {
      skip("build/tools/gpubridge flash --board icebreaker --dry-run",
           "needs an iCEBreaker bitstream, which scripts/gateware.sh cannot build until the up5k design fits; FlashCli.DryRunPrintsTheCommandAndRunsNothing runs it"),
      skip("build/tools/gpubridge flash --board icebreaker",
           "needs an iCEBreaker; FlashCli.FlashesTheBoardsBuiltBitstreamWithOpenFpgaLoader runs it with a stand-in programmer"),
      skip("build/tools/gpubridge flash --board icebreaker --to sram",
           "needs an iCEBreaker; FlashCli.SramGoesThroughIceprogAndJsonReportsIt runs it with a stand-in programmer"),
      run("build/tools/gpubridge bringup --board icebreaker")
          .instead("build/tools/gpubridge bringup --board icebreaker --emulate", "no board here: the chip model and the simulator")
          .prints("PASS"),
  }});

  all.push_back({"docs/daemon.md", "Running", 0, "docs_daemon_Running", {
      daemon("gpubridged").prints("listening on " + kDefaultSocket),
      daemon("gpubridged --listen unix:/tmp/gb.sock --backend fake --log-level debug", "unix:gb.sock")
          .instead("gpubridged --listen unix:gb.sock --backend fake --log-level debug",
                   "/tmp/gb.sock would be shared by test runs in parallel: a path in the private checkout")
          .prints("listening on unix:gb.sock"),
      run("gpubridge status --connect unix:/tmp/gb.sock")
          .instead("gpubridge status --connect unix:gb.sock", "the daemon above, on its private path")
          .prints("daemon: +gpubridged .* at unix:gb.sock")
          .prints("backend: +fake"),
      daemon("gpubridged --config configs/gpubridged.json --listen tcp:127.0.0.1:7420 --listen unix:")
          .instead("gpubridged --config configs/gpubridged.json --listen tcp:127.0.0.1:0 --listen unix:",
                   "port 7420 may be taken by a test run in parallel: port 0 (a free one, printed)")
          .prints(R"(listening on tcp:127\.0\.0\.1:[1-9]\d*)")
          .prints("listening on " + kDefaultSocket),
  }});

  all.push_back({"docs/examples.md", "Running them", 0, "docs_examples_RunningThem", {
      run("build/examples/gpubridge-demo list").prints("tetrahedron").prints("lightmap"),
      run("build/examples/gpubridge-demo render all --out frames --first 0 --frames 8")
          .prints(R"(frames/tetrahedron-0007\.png)")
          .leaves("frames/room-0000.png")
          .leaves("frames/lightmap-0007.png")
          .within(120),
      daemon("build/daemon/gpubridged &"),
      run("build/examples/gpubridge-demo stream room --fps 30").within(120),
      run("build/examples/gpubridge-demo goldens --dir examples/golden")
          .prints(R"(tetrahedron +identical)")
          .prints(R"(lightmap +identical)")
          .within(120),
      skip("build/examples/gpubridge-demo goldens --dir examples/golden --write",
           "rewrites the committed goldens (the line above compares with them)"),
  }});

  all.push_back({"docs/examples.md", "Shift-and-add rotation (CORDIC)", 0, "docs_examples_DonutIdeas", {
      run("build/examples/gpubridge-demo figures --dir docs/screenshots")
          .instead("build/examples/gpubridge-demo figures --dir figures",
                   "the committed figures are not rewritten: the same pictures into a directory of the checkout")
          .prints(R"(dither-temporal-mean16\.png +RGBA2222, temporal dither, mean of 16 frames .*\(mean error [0-9.]+ LSB\))")
          .leaves("figures/dither-temporal-mean16.png")
          .leaves("figures/cordic-4.png")
          .within(180),
      run("build/examples/gpubridge-demo render torus-cordic --cordic-iterations 5 --out frames")
          .prints(R"(frames/torus-cordic-0012\.png)")
          .leaves("frames/torus-cordic-0012.png"),
      skip("build/tools/gpubridge bench accuracy --cordic-only --out-dir docs",
           "rewrites the CORDIC section of docs/accuracy-report.*; CTest bench_accuracy_quick_smoke runs it with --quick "
           "on a copy of a report"),
  }});

  all.push_back({"docs/examples.md", "On every board", 0, "docs_examples_OnEveryBoard", {
      run("build/examples/gpubridge-demo fit --board icebreaker")
          .prints(R"(icebreaker \(iCE40 UP5K; 128 KiB, 320x240 at most)")
          .prints(R"(voxels +256x192 RGBA2222 dithered, double-buffered, painter's order)")
          .prints(R"(gave up: framebuffer 320x240 -> 256x192 \(video memory\))"),
      run("build/examples/gpubridge-demo render tetrahedron --board icebreaker --out small")
          .prints(R"(tetrahedron on icebreaker: 320x240 RGBA2222 dithered, single buffer, painter's order)")
          .leaves("small/tetrahedron-0012.png"),
      run("build/examples/gpubridge-demo render torus --size 160x120 --no-depth --without dither --out forced")
          .prints(R"(gave up: framebuffer 320x240 -> 160x120 \(--size\))")
          .prints(R"(gave up: dither: colour bands instead of the ordered dither \(--without dither\))")
          .leaves("forced/torus-0012.png"),
      run("build/examples/gpubridge-demo fit --timing --markdown")
          .prints(R"(\| example \| ch341a-generic \|)")
          .prints(R"(\| terrain \| 1\.0 \|)")
          .within(120),
  }});

  all.push_back({"docs/viewer.md", "gpubridge-view", 0, "docs_viewer_Start", {
      daemon("gpubridged --backend sim &"),
      // A window the user keeps open (its shell waits); nothing draws in this block.
      viewer("gpubridge-view", {"gpubridge-view - " + kDefaultSocket + " - sim"}),
      skip("gpubridge-view --connect tcp:lab-pc:7420 --token \"$(cat token)\"",
           "needs a daemon on another machine and its token; TCP with a right and a wrong token runs in "
           "tests/viewer (viewer_daemon_test)"),
  }});
  all.push_back({"docs/viewer.md", "Headless use", 0, "docs_viewer_Headless", {
      skip("gpubridge-view --connect unix:/tmp/g.sock --frames 3 --screenshot out.png --offscreen --json",
           "needs a daemon on /tmp/g.sock with a client drawing; these headless options run against a real "
           "daemon in tests/viewer (viewer_daemon_test)"),
  }});
  return all;
}

}  // namespace

const std::vector<Example>& documented_examples() {
  static const std::vector<Example> all = make();
  return all;
}

}  // namespace gpubridge::readme
