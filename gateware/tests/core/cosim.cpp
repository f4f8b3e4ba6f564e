#include "cosim.hpp"

#include <cstring>
#include <sstream>
#include <stdexcept>

#include "gpubridge/protocol/registers.hpp"

namespace gpubridge::rtl {

using protocol::Reg;

namespace {

std::unique_ptr<sim::Device> make_device(const sim::DeviceOptions& o) {
  auto d = sim::Device::create(o);
  if (!d) throw std::runtime_error("simulator options: " + d.error().message);
  return std::move(*d);
}

}  // namespace

Cosim::Cosim(const sim::DeviceOptions& options, std::uint32_t seed, MemoryTiming timing)
    : device_(make_device(options)), core_(options.vram_bytes, seed, timing) {
  for (unsigned i = 0; i < 128; ++i) {
    const auto* d = protocol::find_register(static_cast<std::uint8_t>(i));
    if (d && d->access == protocol::Access::ReadWrite) regs_[i] = device_->read_register(static_cast<std::uint8_t>(i));
  }
}

bool Cosim::range_error_sim() const { return (device_->errors() & protocol::ERR_MEM_RANGE) != 0; }

void Cosim::command(CoreCommand::Op op, const CoreVertex* v) {
  CoreCommand c;
  c.op = op;
  c.tri_mode = static_cast<std::uint32_t>(reg(Reg::TRI_MODE));
  c.tex_base = static_cast<std::uint32_t>(reg(Reg::TEX_BASE));
  c.tex_fmt = static_cast<std::uint32_t>(reg(Reg::TEX_FMT));
  c.scissor = reg(Reg::SCISSOR);
  c.fb_draw = static_cast<std::uint32_t>(reg(Reg::FB_DRAW));
  c.fb_z = static_cast<std::uint32_t>(reg(Reg::FB_Z));
  c.fb_format = reg(Reg::FB_FORMAT);
  c.clear_color = static_cast<std::uint32_t>(reg(Reg::CLEAR_COLOR));
  c.clear_depth = static_cast<std::uint32_t>(reg(Reg::CLEAR_DEPTH));
  if (v)
    for (int i = 0; i < 3; ++i) c.v[i] = v[i];
  core_.submit(c);
  ++commands_;
}

void Cosim::kick(const CoreVertex& a, const CoreVertex& b, const CoreVertex& c) {
  const CoreVertex v[3] = {a, b, c};
  command(CoreCommand::Triangle, v);
}

void Cosim::write(const protocol::Frame& f) {
  device_->write(f);
  if (f.read) return;
  const auto r = static_cast<Reg>(f.index);
  switch (r) {
    case Reg::VERTEX: {
      CoreVertex v;
      v.x = static_cast<std::int16_t>(f.data & 0xFFFF);
      v.y = static_cast<std::int16_t>((f.data >> 16) & 0xFFFF);
      v.z = static_cast<std::uint32_t>((f.data >> 32) & 0xFFFFFF);
      const std::uint64_t col = reg(Reg::COLOR), tc = reg(Reg::TEXCOORD);
      v.rgba = static_cast<std::uint32_t>(col);
      v.q = static_cast<std::uint32_t>(col >> 32);
      v.s = static_cast<std::int32_t>(static_cast<std::uint32_t>(tc >> 32));
      v.t = static_cast<std::int32_t>(static_cast<std::uint32_t>(tc));
      if (count_ < 2) {
        stored_[count_++] = v;
        break;
      }
      kick(stored_[0], stored_[1], v);
      switch (reg(Reg::PRIM) & 3) {
        case 1: stored_[0] = stored_[1]; stored_[1] = v; break;  // STRIP
        case 2: stored_[1] = v; break;                           // FAN
        default: count_ = 0; break;                              // LIST
      }
      break;
    }
    case Reg::PRIM:
      regs_[f.index] = device_->read_register(f.index);
      count_ = 0;
      break;
    case Reg::CLEAR: command(CoreCommand::Clear, nullptr); break;
    case Reg::CLEAR_Z: command(CoreCommand::ClearZ, nullptr); break;
    case Reg::MEM_DATA: {
      // the soc writes memory when the core is idle (FIFO order)
      if (!core_.run_until_idle()) throw std::runtime_error("core did not become idle");
      const std::uint64_t a = reg(Reg::MEM_ADDR);
      auto& m = core_.memory();
      for (unsigned i = 0; i < 8; ++i) {
        if (a + i < m.size()) m[a + i] = static_cast<std::uint8_t>(f.data >> (56 - 8 * i));
        else mem_data_range_ = true;
      }
      regs_[protocol::index_of(Reg::MEM_ADDR)] = (a + 8) & 0xFFFFFFF8u;
      break;
    }
    case Reg::RESET:
      if (f.data == protocol::kResetMagic) {
        for (unsigned i = 0; i < 128; ++i) {
          const auto* d = protocol::find_register(static_cast<std::uint8_t>(i));
          if (d && d->access == protocol::Access::ReadWrite && i != protocol::index_of(Reg::MEM_DATA))
            regs_[i] = device_->read_register(static_cast<std::uint8_t>(i));
        }
        count_ = 0;
      }
      break;
    default: {
      const auto* d = protocol::find_register(f.index);
      if (d && d->access == protocol::Access::ReadWrite && r != Reg::MEM_DATA && r != Reg::FENCE &&
          r != Reg::HOST_TAG && r != Reg::LINK_CTRL)
        regs_[f.index] = device_->read_register(f.index);
      break;
    }
  }
}

void Cosim::upload(std::uint32_t address, const std::uint8_t* bytes, std::size_t length) {
  if (!core_.run_until_idle()) throw std::runtime_error("core did not become idle");
  auto dev = device_->memory();
  auto& m = core_.memory();
  for (std::size_t i = 0; i < length && address + i < m.size(); ++i) {
    dev[address + i] = bytes[i];
    m[address + i] = bytes[i];
  }
}

std::string Cosim::compare() {
  if (!core_.run_until_idle()) return "the core did not become idle";
  const auto dev = device_->memory();
  const auto& m = core_.memory();
  if (std::memcmp(m.data(), dev.data(), m.size()) == 0) return {};
  std::ostringstream out;
  std::size_t diffs = 0;
  for (std::size_t i = 0; i < m.size(); ++i) {
    if (m[i] == dev[i]) continue;
    if (diffs < 12) out << "byte 0x" << std::hex << i << ": core 0x" << unsigned(m[i]) << " sim 0x" << unsigned(dev[i]) << std::dec << "\n";
    ++diffs;
  }
  if (diffs) out << diffs << " bytes differ";
  return out.str();
}

}  // namespace gpubridge::rtl
