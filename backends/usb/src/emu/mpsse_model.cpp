#include "gpubridge/usb/emu/mpsse_model.hpp"

#include <algorithm>
#include <cstdio>
#include <optional>

namespace gpubridge::usb::emu {
namespace {

constexpr std::uint8_t kModemStatus0 = 0x32, kModemStatus1 = 0x60;

std::uint8_t reverse_bits(std::uint8_t b) {
  b = static_cast<std::uint8_t>((b & 0xF0) >> 4 | (b & 0x0F) << 4);
  b = static_cast<std::uint8_t>((b & 0xCC) >> 2 | (b & 0x33) << 2);
  return static_cast<std::uint8_t>((b & 0xAA) >> 1 | (b & 0x55) << 1);
}

std::string hex(unsigned v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", v & 0xFFFFu);
  return buf;
}

}  // namespace

MpsseModel::MpsseModel(MpsseModelConfig cfg, SpiPins* pins) : ChipModel(pins), cfg_(std::move(cfg)) {
  info_.vid = 0x0403;
  switch (cfg_.chip) {
    case FtdiChip::FT232H: info_.pid = 0x6014; info_.bcd_device = 0x0900; info_.product = "FT232H (model)"; break;
    case FtdiChip::FT2232H: info_.pid = 0x6010; info_.bcd_device = 0x0700; info_.product = "FT2232H (model)"; break;
    case FtdiChip::FT4232H: info_.pid = 0x6011; info_.bcd_device = 0x0800; info_.product = "FT4232H (model)"; break;
  }
  info_.manufacturer = "FTDI";
  info_.serial = cfg_.serial;
  info_.port_path = cfg_.port_path;
  info_.bus = 1;
  info_.address = 2;
  info_.high_speed = cfg_.high_speed;
}

std::size_t MpsseModel::tx_fifo_bytes() const {
  switch (cfg_.chip) {
    case FtdiChip::FT232H: return 1024;
    case FtdiChip::FT2232H: return 4096;
    case FtdiChip::FT4232H: return 2048;
  }
  return 1024;
}


int MpsseModel::channel_of_endpoint(std::uint8_t ep, bool in) const {
  const int channels = cfg_.chip == FtdiChip::FT232H ? 1 : 2;
  for (int c = 0; c < channels; ++c) {
    const std::uint8_t want = in ? static_cast<std::uint8_t>(0x81 + 2 * c) : static_cast<std::uint8_t>(0x02 + 2 * c);
    if (ep == want) return c;
  }
  return -1;
}

MpsseModel::Channel* MpsseModel::channel_of_index(std::uint16_t windex) {
  const int channels = cfg_.chip == FtdiChip::FT232H ? 1 : 2;
  if (windex < 1 || windex > channels) return nullptr;
  return &ch_[windex - 1];
}

std::uint16_t MpsseModel::max_packet_size(std::uint8_t endpoint) const {
  const bool in = endpoint & 0x80;
  if (channel_of_endpoint(endpoint, in) < 0) return 0;
  return cfg_.high_speed ? 512 : 64;
}

UsbStatus MpsseModel::detach_kernel_driver(int interface) {
  if (faults_.next() == UsbFault::NoDevice) return UsbStatus::NoDevice;
  const int channels = cfg_.chip == FtdiChip::FT232H ? 1 : 2;
  if (interface < 0 || interface >= channels) return UsbStatus::NotFound;
  if (!ch_[interface].kernel_driver) return UsbStatus::NotFound;
  ch_[interface].kernel_driver = false;
  return UsbStatus::Ok;
}

UsbStatus MpsseModel::claim_interface(int interface) {
  const UsbFault f = faults_.next();
  if (f == UsbFault::NoDevice) return UsbStatus::NoDevice;
  const int channels = cfg_.chip == FtdiChip::FT232H ? 1 : 2;
  if (interface < 0 || interface >= channels) return UsbStatus::NotFound;
  if (ch_[interface].kernel_driver) return UsbStatus::Busy;  // ftdi_sio still bound
  ch_[interface].claimed = true;
  return UsbStatus::Ok;
}

UsbStatus MpsseModel::release_interface(int interface) {
  if (interface < 0 || interface > 1 || !ch_[interface].claimed) return UsbStatus::NotFound;
  ch_[interface].claimed = false;
  return faults_.unplugged ? UsbStatus::NoDevice : UsbStatus::Ok;
}

UsbStatus MpsseModel::clear_halt(std::uint8_t endpoint) {
  if (faults_.unplugged) return UsbStatus::NoDevice;
  return max_packet_size(endpoint) ? UsbStatus::Ok : UsbStatus::NotFound;
}

UsbIo MpsseModel::control_out(std::uint8_t request_type, std::uint8_t request, std::uint16_t value,
                              std::uint16_t index, std::span<const std::uint8_t> data, unsigned) {
  const UsbFault f = faults_.next();
  if (f == UsbFault::NoDevice) return {UsbStatus::NoDevice, 0};
  if (f == UsbFault::Stall) return {UsbStatus::Pipe, 0};
  if (f == UsbFault::TimeoutPartial) return {UsbStatus::Timeout, 0};
  if (request_type != kRequestTypeVendorOut) {
    violation("control OUT with bmRequestType " + hex(request_type));
    return {UsbStatus::Pipe, 0};
  }
  Channel* c = channel_of_index(index);
  if (!c) {
    violation("control request " + hex(request) + " for channel index " + hex(index) + " that this chip lacks");
    return {UsbStatus::Pipe, 0};
  }
  if (!data.empty()) {
    violation("FTDI vendor OUT requests carry no data stage");
    return {UsbStatus::Pipe, 0};
  }
  switch (request) {
    case 0x00:  // SIO_RESET
      if (value == 0) {
        c->pending.clear();
        c->in.clear();
      } else if (value == 1) {
        c->pending.clear();
      } else if (value == 2) {
        c->in.clear();
      } else {
        violation("SIO_RESET with wValue " + hex(value));
        return {UsbStatus::Pipe, 0};
      }
      break;
    case 0x01: case 0x02: case 0x03: case 0x04:  // modem ctrl, flow ctrl, baud, data: accepted, unused in MPSSE
    case 0x06: case 0x07:                         // event / error characters
      break;
    case 0x09:
      if (value < 1 || value > 255) violation("latency timer " + std::to_string(value) + " ms (valid 1..255)");
      c->latency = static_cast<std::uint8_t>(value);
      break;
    case 0x0B: {
      const unsigned mode = value >> 8;
      if (mode == 0x00) {
        c->mpsse = false;
      } else if (mode == 0x02) {
        c->mpsse = true;
        c->pending.clear();
      } else {
        violation("bitmode " + hex(mode) + " is not MPSSE/reset");
        return {UsbStatus::Pipe, 0};
      }
      break;
    }
    default:
      violation("unknown vendor request " + hex(request));
      return {UsbStatus::Pipe, 0};
  }
  return {UsbStatus::Ok, 0};
}

UsbIo MpsseModel::control_in(std::uint8_t request_type, std::uint8_t request, std::uint16_t, std::uint16_t index,
                             std::span<std::uint8_t> data, unsigned) {
  const UsbFault f = faults_.next();
  if (f == UsbFault::NoDevice) return {UsbStatus::NoDevice, 0};
  if (f == UsbFault::Stall) return {UsbStatus::Pipe, 0};
  if (f == UsbFault::TimeoutPartial) return {UsbStatus::Timeout, 0};
  Channel* c = channel_of_index(index);
  if (request_type != kRequestTypeVendorIn || !c) return {UsbStatus::Pipe, 0};
  std::vector<std::uint8_t> reply;
  switch (request) {
    case 0x05: reply = {kModemStatus0, kModemStatus1}; break;
    case 0x0A: reply = {c->latency}; break;
    case 0x0C: reply = {c->low_value}; break;
    default: violation("unknown vendor IN request " + hex(request)); return {UsbStatus::Pipe, 0};
  }
  if (data.size() < reply.size()) return {UsbStatus::Overflow, 0};
  std::copy(reply.begin(), reply.end(), data.begin());
  return {UsbStatus::Ok, reply.size()};
}

UsbIo MpsseModel::bulk_out(std::uint8_t endpoint, std::span<const std::uint8_t> data, unsigned) {
  const UsbFault f = faults_.next();
  if (f == UsbFault::NoDevice) return {UsbStatus::NoDevice, 0};
  if (f == UsbFault::Stall) return {UsbStatus::Pipe, 0};
  const int ch = channel_of_endpoint(endpoint, false);
  if (ch < 0) return {UsbStatus::Io, 0};
  Channel& c = ch_[ch];
  if (!c.claimed) {
    violation("bulk OUT on an unclaimed interface");
    return {UsbStatus::Io, 0};
  }
  std::size_t accepted = data.size();
  if (f == UsbFault::TimeoutPartial) accepted = std::min(faults_.partial_bytes, data.size());
  out_log_.emplace_back(data.begin(), data.begin() + static_cast<std::ptrdiff_t>(accepted));
  if (!c.mpsse) {
    violation("bulk OUT data before MPSSE mode was enabled (goes to the UART)");
    return {UsbStatus::Ok, data.size()};
  }
  c.pending.insert(c.pending.end(), data.begin(), data.begin() + static_cast<std::ptrdiff_t>(accepted));
  run(ch);
  if (c.pending.size() > tx_fifo_bytes()) {
    // The MPSSE is stalled (RX FIFO full or waiting on BUSY) and the TX FIFO is full: the chip NAKs
    // the rest of the OUT transfer until the host's timeout.
    const std::size_t refused = c.pending.size() - tx_fifo_bytes();
    c.pending.resize(tx_fifo_bytes());
    return {UsbStatus::Timeout, accepted > refused ? accepted - refused : 0};
  }
  if (f == UsbFault::TimeoutPartial) return {UsbStatus::Timeout, accepted};
  return {UsbStatus::Ok, data.size()};
}

UsbIo MpsseModel::bulk_in(std::uint8_t endpoint, std::span<std::uint8_t> data, unsigned) {
  const UsbFault f = faults_.next();
  if (f == UsbFault::NoDevice) return {UsbStatus::NoDevice, 0};
  if (f == UsbFault::Stall) return {UsbStatus::Pipe, 0};
  const int ch = channel_of_endpoint(endpoint, true);
  if (ch < 0) return {UsbStatus::Io, 0};
  Channel& c = ch_[ch];
  if (!c.claimed) return {UsbStatus::Io, 0};
  run(ch);  // time passed: stalled waits may have completed
  const std::size_t limit = f == UsbFault::TimeoutPartial ? std::min(data.size(), faults_.partial_bytes) : data.size();
  const auto packed = pack_in(c, data, limit);
  if (!packed) return {UsbStatus::Overflow, 0};  // babble: the packet does not fit the buffer
  return {f == UsbFault::TimeoutPartial ? UsbStatus::Timeout : UsbStatus::Ok, *packed};
}

std::optional<std::size_t> MpsseModel::pack_in(Channel& c, std::span<std::uint8_t> data, std::size_t limit) {
  const std::size_t mps = cfg_.high_speed ? 512 : 64;
  std::size_t pos = 0;
  do {
    const std::size_t payload = std::min(mps - 2, c.in.size());
    const std::size_t packet = payload + 2;
    if (pos + packet > data.size()) {
      if (pos == 0) return std::nullopt;
      break;
    }
    if (pos + packet > limit) break;
    data[pos] = kModemStatus0;
    data[pos + 1] = kModemStatus1;
    for (std::size_t i = 0; i < payload; ++i) {
      data[pos + 2 + i] = c.in.front();
      c.in.pop_front();
    }
    pos += packet;
    if (packet < mps) break;  // short packet ends the transfer
  } while (!c.in.empty());
  return pos;
}

// The host keeps OUT and IN transfers queued at once; the model serialises that into one valid
// schedule: the chip takes OUT bytes while its TX FIFO has room (the MPSSE stalls once its RX FIFO
// is full), then one queued IN transfer drains what is waiting. Each OUT transfer and each IN
// transfer is one operation of the fault plan, as it is one URB on a real bus.
BulkStreamResult MpsseModel::bulk_stream(const BulkStream& s, const InSink& on_in) {
  BulkStreamResult res;
  const int ch = channel_of_endpoint(s.out_endpoint, false);
  if (ch < 0 || channel_of_endpoint(s.in_endpoint, true) != ch || s.out_chunk == 0 || s.in_transfer_bytes == 0) {
    violation("bulk stream on endpoints " + hex(s.out_endpoint) + "/" + hex(s.in_endpoint) + " that are not one channel's pair");
    return {UsbStatus::Io, 0, 0, 0};
  }
  Channel& c = ch_[ch];
  if (!c.claimed) {
    violation("bulk stream on an unclaimed interface");
    return {UsbStatus::Io, 0, 0, 0};
  }
  if (!c.mpsse) violation("bulk stream before MPSSE mode was enabled (goes to the UART)");
  std::vector<std::uint8_t> in_buf(s.in_transfer_bytes);
  std::size_t transfer_end = 0;  // end of the OUT transfer being taken by the chip (0 = none started)
  bool consumer_done = false;
  auto fail = [&](UsbStatus st) {
    res.status = st;
    return res;
  };
  while (res.out_transferred < s.out.size() || !consumer_done) {
    bool progressed = false;
    if (res.out_transferred < s.out.size()) {
      if (transfer_end <= res.out_transferred) {
        const UsbFault f = faults_.next();
        if (f == UsbFault::NoDevice) return fail(UsbStatus::NoDevice);
        if (f == UsbFault::Stall) return fail(UsbStatus::Pipe);
        transfer_end = std::min(s.out.size(), res.out_transferred + s.out_chunk);
        if (f == UsbFault::TimeoutPartial) {
          const std::size_t n = std::min(faults_.partial_bytes, transfer_end - res.out_transferred);
          const auto part = s.out.subspan(res.out_transferred, n);
          out_log_.emplace_back(part.begin(), part.end());
          c.pending.insert(c.pending.end(), part.begin(), part.end());
          run(ch);
          res.out_transferred += n;
          return fail(UsbStatus::Timeout);
        }
      }
      const std::size_t room = tx_fifo_bytes() - std::min(tx_fifo_bytes(), c.pending.size());
      const std::size_t n = std::min(room, transfer_end - res.out_transferred);
      if (n > 0) {
        const auto part = s.out.subspan(res.out_transferred, n);
        out_log_.emplace_back(part.begin(), part.end());
        c.pending.insert(c.pending.end(), part.begin(), part.end());
        res.out_transferred += n;
        if (res.out_transferred == transfer_end) ++res.out_transfers;
        progressed = true;
      }
      run(ch);
    }
    if (!consumer_done) {
      const UsbFault f = faults_.next();
      if (f == UsbFault::NoDevice) return fail(UsbStatus::NoDevice);
      if (f == UsbFault::Stall) return fail(UsbStatus::Pipe);
      run(ch);
      const std::size_t limit = f == UsbFault::TimeoutPartial ? std::min(in_buf.size(), faults_.partial_bytes) : in_buf.size();
      const auto packed = pack_in(c, in_buf, limit);
      ++res.in_transfers;
      if (!packed) return fail(UsbStatus::Overflow);
      if (f == UsbFault::TimeoutPartial) return fail(UsbStatus::Timeout);
      const StreamStep step = on_in(std::span<const std::uint8_t>(in_buf).first(*packed));
      if (step == StreamStep::Abort) return res;
      consumer_done = step == StreamStep::Done;
      progressed = true;
    }
    // Consumer satisfied but the chip takes no more OUT bytes: the host's OUT transfer times out.
    if (!progressed) return fail(UsbStatus::Timeout);
  }
  return res;
}

void MpsseModel::run(int ch) {
  Channel& c = ch_[ch];
  std::size_t off = 0;
  while (off < c.pending.size()) {
    bool stalled = false;
    const std::size_t n = execute(ch, std::span<const std::uint8_t>(c.pending).subspan(off), stalled);
    if (n == 0) break;
    off += n;
  }
  c.pending.erase(c.pending.begin(), c.pending.begin() + static_cast<std::ptrdiff_t>(off));
}

std::uint32_t MpsseModel::sck_hz() const {
  const Channel& c = ch_[0];
  const std::uint32_t base = c.div5 ? 12'000'000u : 60'000'000u;
  return base / ((1u + c.divisor) * 2u);
}

void MpsseModel::update_cs(Channel& c) {
  if (&c != &ch_[0] || !pins_) return;
  const std::uint8_t bit = static_cast<std::uint8_t>(1u << cfg_.cs_pin);
  const bool driven_low = (c.low_dir & bit) && !(c.low_value & bit);
  if (driven_low != pins_->cs_asserted()) pins_->set_cs(driven_low);
}

std::uint8_t MpsseModel::shift(Channel& c, std::uint8_t mosi, bool write, unsigned bits) {
  if (!write) mosi = (c.low_value & 0x02) ? 0xFF : 0x00;  // DO holds its last level
  std::uint8_t in = 0;
  for (unsigned i = 0; i < bits; ++i) {
    const bool out_bit = (mosi >> (7 - i)) & 1u;
    bool miso_bit = true;  // DI pulled up with nothing attached
    if (c.loopback) miso_bit = out_bit;
    else if (&c == &ch_[0] && pins_) miso_bit = pins_->shift_bit(out_bit);
    in = static_cast<std::uint8_t>(in << 1 | (miso_bit ? 1 : 0));
    if (write) c.low_value = static_cast<std::uint8_t>((c.low_value & ~0x02) | (out_bit ? 0x02 : 0));
  }
  return in;
}

std::size_t MpsseModel::execute(int ch, std::span<const std::uint8_t> cmd, bool& stalled) {
  Channel& c = ch_[ch];
  const std::uint8_t op = cmd[0];
  auto bad_command = [&](std::uint8_t b) {
    c.in.push_back(0xFA);
    c.in.push_back(b);
    return std::size_t{1};
  };
  const std::size_t rx_cap = rx_fifo_bytes();

  if (!(op & 0x80)) {
    const bool tms = op & 0x40, write = op & 0x10, read = op & 0x20, bit_mode = op & 0x02;
    if (!(write || read || tms)) {
      violation("opcode " + hex(op) + " is neither a data nor a control command");
      return bad_command(op);
    }
    if (tms) {
      if (cmd.size() < 3) return 0;
      violation("JTAG TMS command " + hex(op) + " sent to an SPI board");
      if (read) c.in.push_back(0);
      return 3;
    }
    if (write && !(op & 0x01)) violation("opcode " + hex(op) + " writes on the rising edge: SPI mode 0 needs the falling edge");
    if (!(c.low_dir & 0x01) || (write && !(c.low_dir & 0x02)))
      violation("data command " + hex(op) + " while SK/DO are not outputs (send 0x80 first)");
    if (pins_ && ch == 0) pins_->set_clock_hz(sck_hz());
    const bool lsb = op & 0x08;
    if (bit_mode) {
      const std::size_t need = write ? 3 : 2;
      if (cmd.size() < need) return 0;
      if (cmd[1] > 7) violation("bit command length " + std::to_string(cmd[1] + 1) + " exceeds 8");
      if (read && c.in.size() >= rx_cap) { stalled = true; return 0; }
      const unsigned bits = (cmd[1] & 7u) + 1;
      std::uint8_t out = write ? cmd[2] : 0;
      if (lsb) out = reverse_bits(out);
      const std::uint8_t got = shift(c, out, write, bits);
      if (read) c.in.push_back(lsb ? reverse_bits(static_cast<std::uint8_t>(got << (8 - bits))) : got);
      return need;
    }
    if (cmd.size() < 3) return 0;
    const std::size_t n = (std::size_t{cmd[1]} | std::size_t{cmd[2]} << 8) + 1;  // 1..65536 by construction
    if (write && cmd.size() < 3 + n) return 0;
    if (read && !c.in.empty() && c.in.size() + n > rx_cap) { stalled = true; return 0; }
    for (std::size_t i = 0; i < n; ++i) {
      std::uint8_t out = write ? cmd[3 + i] : 0;
      if (lsb) out = reverse_bits(out);
      std::uint8_t got = shift(c, out, write, 8);
      if (lsb) got = reverse_bits(got);
      if (read) c.in.push_back(got);
    }
    return write ? 3 + n : 3;
  }

  switch (op) {
    case 0x80:
    case 0x82:
      if (op == 0x82 && cfg_.chip == FtdiChip::FT4232H) return bad_command(op);  // no high byte on FT4232H
      if (cmd.size() < 3) return 0;
      if (op == 0x80) {
        c.low_value = cmd[1];
        c.low_dir = cmd[2];
        update_cs(c);
      } else {
        c.high_value = cmd[1];
        c.high_dir = cmd[2];
      }
      return 3;
    case 0x81:
    case 0x83: {
      std::uint8_t v = op == 0x81 ? c.low_value : c.high_value;
      if (op == 0x81 && ch == 0 && pins_ && cfg_.busy_wired) v = static_cast<std::uint8_t>((v & ~0x20) | (pins_->busy_pin() ? 0x20 : 0));
      c.in.push_back(v);
      return 1;
    }
    case 0x84: c.loopback = true; return 1;
    case 0x85: c.loopback = false; return 1;
    case 0x86:
      if (cmd.size() < 3) return 0;
      c.divisor = static_cast<std::uint16_t>(cmd[1] | cmd[2] << 8);
      return 3;
    case 0x87: return 1;  // the model hands every byte to the host at once
    case 0x88:
    case 0x89: {
      const bool want_high = op == 0x88;
      auto pin_high = [&] { return ch == 0 && pins_ && cfg_.busy_wired && pins_->busy_pin(); };
      for (unsigned t = 0; pin_high() != want_high; ++t) {
        if (t >= cfg_.max_wait_ticks || !pins_ || !cfg_.busy_wired) {
          stalled = true;  // waits until the host's timeout: the pin never changes
          return 0;
        }
        pins_->idle_tick();
      }
      return 1;
    }
    case 0x8A: c.div5 = false; return 1;
    case 0x8B: c.div5 = true; return 1;
    case 0x8C: c.three_phase = true; violation("3-phase clocking enabled: SPI mode 0 would see an extra half cycle"); return 1;
    case 0x8D: c.three_phase = false; return 1;
    case 0x8E:
      if (cmd.size() < 2) return 0;
      shift(c, 0, false, (cmd[1] & 7u) + 1);
      return 2;
    case 0x8F: {
      if (cmd.size() < 3) return 0;
      const std::size_t n = (std::size_t{cmd[1]} | std::size_t{cmd[2]} << 8) + 1;
      for (std::size_t i = 0; i < n; ++i) shift(c, 0, false, 8);
      return 3;
    }
    case 0x96: c.adaptive = true; violation("adaptive clocking needs RTCK, which SPI boards lack"); return 1;
    case 0x97: c.adaptive = false; return 1;
    case 0x9E:
      if (cfg_.chip != FtdiChip::FT232H) return bad_command(op);
      if (cmd.size() < 3) return 0;
      return 3;
    default:
      return bad_command(op);
  }
}

}  // namespace gpubridge::usb::emu
