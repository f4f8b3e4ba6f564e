#pragma once
// The dispatcher: the GPU's command decode (DMC_1_gpu's dispatch and the span drawer's in_start).
// Parameters update the registers at once; spans are turned into self-contained jobs for the
// command FIFO, with the registers they read captured and the registers they change (the running
// dot products, the texture binding, the terrain state) advanced as the hardware advances them.
#include <cstdint>
#include <memory>

#include "command_fifo.hpp"
#include "gpubridge/dmc1/device.hpp"
#include "gpubridge/dmc1/texture_memory.hpp"
#include "gpubridge/dmc1/timing.hpp"
#include "parameter_registers.hpp"

namespace gpubridge::dmc1 {

class Dispatcher {
 public:
  explicit Dispatcher(std::shared_ptr<const TextureMemory> textures) : textures_(std::move(textures)) {}

  // Decodes one command word into the FIFO (which must not be full).
  void push(std::uint64_t word, CommandFifo& fifo, TimingModel& timing, DeviceStats& stats);

  unsigned draw_buffer() const { return draw_buffer_; }
  unsigned column() const { return column_; }
  const ParameterRegisters& registers() const { return regs_; }
  void reset() {
    regs_ = {};
    draw_buffer_ = 0;
    column_ = 0;
  }

 private:
  void span(std::uint64_t word, CommandKind kind, CommandFifo& fifo, TimingModel& timing, DeviceStats& stats);
  // Runs the terrain event machine; returns the number of events.
  std::uint32_t terrain(std::uint64_t word, unsigned start, unsigned end, SpanJob& job, CommandFifo& fifo);

  std::shared_ptr<const TextureMemory> textures_;
  ParameterRegisters regs_;
  unsigned draw_buffer_ = 0;  // column buffer the drawer writes; flips at every end of column
  unsigned column_ = 0;       // screen column the next end of column outputs
};

}  // namespace gpubridge::dmc1
