#pragma once
// The gateware as a chip on a board: the Verilated spigpu device (gateware/sim/spigpu_sim.v) driven
// at its pins on a time axis. The SPI master (a bridge chip model) changes CS, SCK and MOSI at
// instants of an SCK timeline; the core clock runs independently (its own period and phase), and
// the device samples the pins through its synchronisers exactly as the hardware would. MISO is read
// where the host samples it (rising or falling SCK edge, profile read_edge), as it was
// miso_delay_ns earlier (device clock-to-pad + wiring + host setup time), so a design that is late
// returns wrong bits here as on a board.
//
// Besides the pins, the bench around the board can: read video memory (backdoor), collect the
// frames the scanout reads (the video output), and read the device's counters.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "gpubridge/common/result.hpp"
#include "gpubridge/protocol/registers.hpp"
#include "gpubridge/rtl/gateware_profile.hpp"

namespace gpubridge::rtl {

struct PinTiming {
  double core_hz = 0;            // 0: the profile's clock (caps_of(profile).core_hz)
  double sck_hz = 10e6;          // SPI clock until the bridge sets another (set_sck_hz)
  bool sample_falling = true;    // the host samples MISO on the falling SCK edge
  double miso_delay_ns = 20;     // MISO valid this long after the device's clock edge
  double phase = 0.37;           // core clock phase at time 0, in core periods (0..1)
};

struct ScanFrame {
  std::uint32_t number = 0;  // 1 for the first frame after power-on
  unsigned width = 0, height = 0;
  protocol::PixelFormat format = protocol::PixelFormat::RGBA8888;
  std::vector<std::uint8_t> bytes;  // width * height * bpp, as the scanout read them
};

struct RtlCounters {
  std::uint64_t cycles = 0;            // core clocks since power-on
  std::uint64_t work_cycles = 0;       // clocks with a released command, the core or MEM_* working
  std::uint64_t commands = 0;          // FIFO entries executed
  std::uint64_t spi_frames = 0;        // SPI frames completed
  std::uint64_t core_mem_stalls = 0;   // clocks a core memory request waited
  // the render core's counters (gateware/rtl/core/spigpu_core.v)
  std::uint64_t triangles = 0;         // triangles rasterised (non-empty after setup)
  std::uint64_t pixels = 0;            // covered pixels emitted by the rasteriser
  std::uint64_t passed = 0;            // pixels that passed the depth stage
  std::uint64_t textured = 0;          // pixels through the texture unit
  std::uint64_t core_busy_cycles = 0;  // clocks the core was not idle
  std::uint64_t setup_cycles = 0;      // clocks in triangle setup
  std::uint64_t raster_cycles = 0;     // clocks the rasteriser walked
  std::uint64_t refreshes = 0;         // SDRAM auto refreshes
  std::uint64_t sdram_violations = 0;  // timing violations seen by the SDRAM model (must stay 0)
  std::uint64_t sck_edges_too_fast = 0;  // SCK half periods shorter than a core clock (pins outside spec)
};
// The counts between two readings (later - earlier): what one frame or one draw took.
RtlCounters operator-(const RtlCounters& later, const RtlCounters& earlier);

class RtlDevice {
 public:
  // True when the build has the Verilated models (Verilator was installed).
  static bool available();
  // Why the backend is absent (empty when available).
  static std::string unavailable_reason();

  static Result<std::unique_ptr<RtlDevice>> create(GatewareProfile profile, PinTiming timing = {});
  ~RtlDevice();
  RtlDevice(const RtlDevice&) = delete;
  RtlDevice& operator=(const RtlDevice&) = delete;

  GatewareProfile profile() const;
  const GatewareCaps& caps() const;
  const PinTiming& timing() const;

  // --- pins, as an SPI master drives them ---
  void set_cs(bool asserted);                 // CS low = asserted; waits the CS setup/hold time
  bool cs_asserted() const;
  bool shift_bit(bool mosi);                  // one SCK period; returns the MISO bit the host samples
  std::uint8_t shift_byte(std::uint8_t mosi); // MSB first
  bool busy_pin() const;
  void set_sck_hz(double hz);
  void idle_ns(double ns);                    // time passes, SPI idle
  void idle_clocks(std::uint64_t clocks);
  // Holds the reset input for a few clocks (power-on state; memory contents are kept).
  void power_cycle();

  // --- the bench ---
  std::uint64_t vram_bytes() const;
  void read_vram(std::uint64_t address, std::uint8_t* out, std::size_t length) const;
  std::vector<std::uint8_t> vram() const;
  // Called for every frame the scanout has read completely, from inside the pin calls.
  void set_frame_callback(std::function<void(const ScanFrame&)> cb);
  RtlCounters counters() const;
  double now_ns() const;

  struct Impl;

 private:
  explicit RtlDevice(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace gpubridge::rtl
