#pragma once
// Co-simulation of the render core against the C++ simulator: register frames go to a
// sim::Device and, through a small model of the soc's register file and primitive assembly
// (docs/protocol.md sections 5 and 7), become commands for the Verilated core. Register values
// are the device's own validated ones (read back after each write), so both see the same
// state. Memory writes through MEM_ADDR/MEM_DATA reach both memories.
#include <cstdint>
#include <memory>
#include <string>

#include "core_harness.hpp"
#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/sim/device.hpp"

namespace gpubridge::rtl {

class Cosim {
 public:
  Cosim(const sim::DeviceOptions& options, std::uint32_t seed, MemoryTiming timing = {});

  void write(const protocol::Frame& f);
  void write(protocol::Reg r, std::uint64_t data) { write(protocol::write_frame(r, data)); }
  // Direct memory upload to both (the simulator's fast path; the core must be idle).
  void upload(std::uint32_t address, const std::uint8_t* bytes, std::size_t length);

  // Runs the core until idle and compares video memory byte for byte. Empty when equal,
  // otherwise a description of the first differences.
  std::string compare();
  // ERR_MEM_RANGE as raised by the core's accesses (and MEM_DATA writes) vs the simulator.
  bool range_error_core() const { return core_.range_error() || mem_data_range_; }
  bool range_error_sim() const;

  sim::Device& device() { return *device_; }
  CoreHarness& core() { return core_; }
  std::uint64_t commands() const { return commands_; }

 private:
  void kick(const CoreVertex& a, const CoreVertex& b, const CoreVertex& c);
  void command(CoreCommand::Op op, const CoreVertex* v);
  std::uint64_t reg(protocol::Reg r) const { return regs_[protocol::index_of(r)]; }

  std::unique_ptr<sim::Device> device_;
  CoreHarness core_;
  std::uint64_t regs_[128] = {};
  CoreVertex stored_[2];
  unsigned count_ = 0;
  bool mem_data_range_ = false;
  std::uint64_t commands_ = 0;
};

}  // namespace gpubridge::rtl
