// FTDI MPSSE SPI driver. Init order follows usb-spi-bridges.md 1.4; commands are batched into
// bulk OUTs of at most the chip's FIFO size and the IN side is read in rounds that fit the
// chip's RX FIFO, so the synchronous libusb API never deadlocks against a full chip.
#include "gpubridge/usb/ftdi_mpsse.hpp"

#include <algorithm>
#include <chrono>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/common/log.hpp"
#include "gpubridge/usb/usb_errors.hpp"

namespace gpubridge::usb {
namespace {

constexpr std::uint8_t kSioReset = 0x00, kSetEventChar = 0x06, kSetErrorChar = 0x07, kSetLatency = 0x09,
                       kSetBitmode = 0x0B;
constexpr std::uint8_t kSetBitsLow = 0x80, kSetDivisor = 0x86, kSendImmediate = 0x87, kWaitGpiol1Low = 0x89,
                       kDisableDiv5 = 0x8A, kDisableAdaptive = 0x97, kDisable3Phase = 0x8D, kLoopbackOff = 0x85;
constexpr std::uint8_t kWriteBytesNeg = 0x11, kDuplexReadPos = 0x31, kDuplexReadNeg = 0x35;
constexpr std::size_t kMaxCommandBytes = 65536;
// Status-only IN transfers tolerated while waiting for data (bounded polling of a stalled chip).
constexpr unsigned kMaxEmptyTransfers = 4096;

// A transport must never report more IN bytes than the buffer holds; trusting such a count read
// past the buffer (found by fuzz_usb_bridges).
Error over_long_in(const std::string& where, std::size_t transferred, std::size_t buffer) {
  return make_error(where + ": bulk IN reported " + std::to_string(transferred) + " bytes for a " + std::to_string(buffer) +
                        "-byte buffer (USB transport fault)",
                    backends::kDeviceProtocol);
}

}  // namespace

std::size_t ftdi_fifo_bytes(std::uint16_t bcd) {
  switch (bcd) {
    case 0x0700: return 4096;
    case 0x0800: case 0x3600: return 2048;
    default: return 1024;
  }
}

std::string_view ftdi_chip_name(std::uint16_t bcd) {
  switch (bcd) {
    case 0x0900: return "FT232H";
    case 0x0700: return "FT2232H";
    case 0x0800: return "FT4232H";
    case 0x3600: return "FT4232HA";
    default: return "FTDI (unknown bcdDevice)";
  }
}

FtdiMpsseBridge::FtdiMpsseBridge(UsbDevice& dev, FtdiConfig cfg)
    : dev_(dev),
      cfg_(cfg),
      ep_in_(static_cast<std::uint8_t>(0x81 + 2 * cfg.channel)),
      ep_out_(static_cast<std::uint8_t>(0x02 + 2 * cfg.channel)),
      windex_(static_cast<std::uint16_t>(cfg.channel + 1)),
      idle_value_(static_cast<std::uint8_t>(1u << cfg.cs_pin)),
      direction_(static_cast<std::uint8_t>(0x03 | 1u << cfg.cs_pin)) {}

std::string FtdiMpsseBridge::where() const {
  const auto& i = dev_.info();
  return std::string(ftdi_chip_name(i.bcd_device)) + " channel " + static_cast<char>('A' + cfg_.channel) +
         " (port " + (i.port_path.empty() ? "?" : i.port_path) + (i.serial.empty() ? "" : ", serial " + i.serial) + ")";
}

Result<std::unique_ptr<FtdiMpsseBridge>> FtdiMpsseBridge::open(UsbDevice& dev, FtdiConfig cfg) {
  const auto bcd = dev.info().bcd_device;
  if (bcd != 0x0700 && bcd != 0x0800 && bcd != 0x0900 && bcd != 0x3600)
    return make_error(fmt::format("FTDI device with bcdDevice 0x{:04X}", bcd) +
                          " is not an H-series MPSSE chip (FT232H/FT2232H/FT4232H); use a different adapter",
                      backends::kBadRequest);
  const int channels = bcd == 0x0900 ? 1 : 2;
  if (cfg.channel < 0 || cfg.channel >= channels)
    return make_error("board profile asks for FTDI channel " + std::string(1, static_cast<char>('A' + cfg.channel)) + " but " +
                          std::string(ftdi_chip_name(bcd)) + " has MPSSE only on channel" + (channels == 1 ? " A" : "s A and B"),
                      backends::kBadRequest);
  if (cfg.cs_pin < 3 || cfg.cs_pin > 7 || (cfg.busy_pin && cfg.cs_pin == 5))
    return make_error("FTDI chip select must be ADBUS3..7 and not ADBUS5 when BUSY is wired (ADBUS0-2 are SK/DO/DI, ADBUS5 is GPIOL1)",
                      backends::kBadRequest);
  std::unique_ptr<FtdiMpsseBridge> b(new FtdiMpsseBridge(dev, cfg));
  if (auto r = b->init(); !r) return r.error();
  return b;
}

FtdiMpsseBridge::~FtdiMpsseBridge() {
  if (!claimed_) return;
  // Leave the pins released (bitmode reset) so the FPGA's CS floats high; errors are moot here.
  (void)dev_.control_out(kRequestTypeVendorOut, kSetBitmode, 0x0000, windex_, {}, cfg_.timeout_ms);
  (void)dev_.release_interface(cfg_.channel);
}

Result<void> FtdiMpsseBridge::control(std::uint8_t request, std::uint16_t value, const char* what) {
  ++stats_.control_transfers;
  const UsbIo io = dev_.control_out(kRequestTypeVendorOut, request, value, windex_, {}, cfg_.timeout_ms);
  if (!io.ok()) return usb_error(io.status, where() + ": " + what);
  return {};
}

Result<void> FtdiMpsseBridge::init() {
  packet_size_ = dev_.max_packet_size(ep_in_);
  if (packet_size_ <= 2) return make_error(where() + ": IN endpoint has no usable wMaxPacketSize", backends::kDeviceProtocol);
  fifo_ = ftdi_fifo_bytes(dev_.info().bcd_device);

  const UsbStatus d = dev_.detach_kernel_driver(cfg_.channel);
  if (d != UsbStatus::Ok && d != UsbStatus::NotFound && d != UsbStatus::NotSupported)
    return usb_error(d, where() + ": detach kernel driver ftdi_sio");
  if (const UsbStatus c = dev_.claim_interface(cfg_.channel); c != UsbStatus::Ok)
    return usb_error(c, where() + ": claim interface");
  claimed_ = true;
  if (auto r = control(kSioReset, 0, "reset"); !r) return r;
  if (auto r = control(kSioReset, 1, "purge host-to-chip FIFO"); !r) return r;
  if (auto r = control(kSioReset, 2, "purge chip-to-host FIFO"); !r) return r;
  if (auto r = control(kSetEventChar, 0, "disable event character"); !r) return r;
  if (auto r = control(kSetErrorChar, 0, "disable error character"); !r) return r;
  if (auto r = control(kSetLatency, cfg_.latency_ms, "set latency timer"); !r) return r;
  if (auto r = control(kSetBitmode, 0x0000, "reset bitmode"); !r) return r;
  if (auto r = control(kSetBitmode, static_cast<std::uint16_t>(0x0200 | direction_), "enable MPSSE"); !r) return r;
  return recover();
}

Result<void> FtdiMpsseBridge::recover() {
  if (auto r = control(kSioReset, 1, "purge host-to-chip FIFO"); !r) return r;
  if (auto r = control(kSioReset, 2, "purge chip-to-host FIFO"); !r) return r;
  // Drain stale IN bytes: stop at the first status-only packet (bounded).
  std::vector<std::uint8_t> buf(packet_size_);
  for (int i = 0; i < 16; ++i) {
    const UsbIo io = dev_.bulk_in(ep_in_, buf, cfg_.timeout_ms);
    ++stats_.usb_in_transfers;
    if (!io.ok()) return usb_error(io.status, where() + ": drain stale data");
    if (io.transferred > buf.size()) return over_long_in(where(), io.transferred, buf.size());
    if (io.transferred <= 2) break;
  }
  const std::uint8_t setup[] = {kDisableDiv5, kDisableAdaptive, kDisable3Phase, kLoopbackOff, kSetBitsLow, idle_value_, direction_};
  if (auto r = write_all(setup); !r) return r;
  if (auto r = set_clock(cfg_.clock_hz); !r) return r.error();
  return sync_check();
}

// The chip answers an unknown opcode with FA <opcode>: a cheap proof the command stream is in step.
Result<void> FtdiMpsseBridge::sync_check() {
  const std::uint8_t probe[] = {0xAB, kSendImmediate};
  if (auto r = write_all(probe); !r) return r;
  std::uint8_t reply[2] = {};
  if (auto r = read_exact(reply); !r) return r;
  if (reply[0] != 0xFA || reply[1] != 0xAB)
    return make_error(where() + ": MPSSE sync check failed (sent AB, expected FA AB); the chip is not in MPSSE mode or "
                                "the command stream is out of step — replug the adapter",
                      backends::kDeviceProtocol);
  return {};
}

Result<std::uint32_t> FtdiMpsseBridge::set_clock(std::uint32_t hz) {
  if (hz < 500) return make_error(where() + ": SPI clock " + std::to_string(hz) + " Hz is below the MPSSE minimum (~458 Hz)",
                                  backends::kBadRequest);
  hz = std::min<std::uint32_t>(hz, 30'000'000);
  const std::uint32_t divisor = (30'000'000u + hz - 1) / hz - 1;  // 60 MHz / ((1 + d) * 2) <= hz
  const std::uint8_t cmd[] = {kSetDivisor, static_cast<std::uint8_t>(divisor & 0xFF), static_cast<std::uint8_t>(divisor >> 8)};
  if (auto r = write_all(cmd); !r) return r.error();
  clock_hz_ = 60'000'000u / ((1 + divisor) * 2);
  cfg_.clock_hz = hz;
  return clock_hz_;
}

Result<void> FtdiMpsseBridge::write_all(std::span<const std::uint8_t> bytes) {
  std::size_t off = 0;
  bool retried_stall = false;
  while (off < bytes.size()) {
    const auto chunk = bytes.subspan(off, std::min(fifo_, bytes.size() - off));
    const UsbIo io = dev_.bulk_out(ep_out_, chunk, cfg_.timeout_ms);
    ++stats_.usb_out_transfers;
    stats_.usb_bytes_out += io.transferred;
    if (io.status == UsbStatus::Pipe && io.transferred == 0 && !retried_stall) {
      retried_stall = true;  // a stall is cleared and retried once
      if (dev_.clear_halt(ep_out_) == UsbStatus::Ok) continue;
    }
    if (!io.ok()) return usb_error(io.status, where() + ": bulk OUT (" + std::to_string(io.transferred) + " of " +
                                                  std::to_string(chunk.size()) + " bytes sent)");
    off += chunk.size();
  }
  return {};
}

Result<bool> FtdiMpsseBridge::collect_in(InCollector& c, std::span<const std::uint8_t> transfer) const {
  // Two modem-status bytes start every wMaxPacketSize chunk of what actually arrived.
  bool had_data = false;
  for (std::size_t p = 0; p < transfer.size(); p += packet_size_) {
    const std::size_t len = std::min<std::size_t>(packet_size_, transfer.size() - p);
    if (len <= 2) continue;
    const std::size_t n = len - 2;
    if (c.got + n > c.out.size())
      return make_error(where() + ": chip sent " + std::to_string(c.got + n - c.out.size()) +
                            " unexpected bytes (MPSSE command stream out of step); the bridge will be re-initialised",
                        backends::kDeviceProtocol);
    std::copy_n(transfer.begin() + static_cast<std::ptrdiff_t>(p + 2), n, c.out.begin() + static_cast<std::ptrdiff_t>(c.got));
    c.got += n;
    had_data = true;
  }
  const auto now = std::chrono::steady_clock::now();
  if (had_data) {
    c.empty_transfers = 0;
    c.last_data = now;
  } else if (c.got < c.out.size() &&
             (++c.empty_transfers > kMaxEmptyTransfers || now - c.last_data > std::chrono::milliseconds(cfg_.timeout_ms))) {
    // Status-only packets (the latency timer expired with nothing to send) for too long.
    return make_error(where() + ": no data from the chip after " + std::to_string(c.empty_transfers) +
                          " polls (waiting on BUSY or the chip stalled); check the board is powered and configured",
                      backends::kDeviceTimeout);
  }
  return c.got == c.out.size();
}

Result<void> FtdiMpsseBridge::read_exact(std::span<std::uint8_t> out) {
  InCollector c{out, 0, 0, std::chrono::steady_clock::now()};
  bool retried_stall = false;
  std::vector<std::uint8_t> buf;
  ++stats_.round_trips;
  while (c.got < out.size()) {
    const std::size_t payload_per_packet = packet_size_ - 2u;
    const std::size_t packets = std::min<std::size_t>((out.size() - c.got + payload_per_packet - 1) / payload_per_packet, 128);
    buf.resize(packets * packet_size_);
    const UsbIo io = dev_.bulk_in(ep_in_, buf, cfg_.timeout_ms);
    ++stats_.usb_in_transfers;
    stats_.usb_bytes_in += io.transferred;
    if (io.status == UsbStatus::Pipe && !retried_stall) {
      retried_stall = true;
      if (dev_.clear_halt(ep_in_) == UsbStatus::Ok) continue;
    }
    if (!io.ok()) return usb_error(io.status, where() + ": bulk IN (" + std::to_string(c.got) + " of " +
                                                  std::to_string(out.size()) + " bytes received)");
    if (io.transferred > buf.size()) return over_long_in(where(), io.transferred, buf.size());
    if (auto r = collect_in(c, std::span<const std::uint8_t>(buf).first(io.transferred)); !r) return r.error();
  }
  return {};
}

Result<std::optional<std::vector<std::uint8_t>>> FtdiMpsseBridge::stream_transfer(std::span<const std::uint8_t> cmd,
                                                                                  std::size_t in_bytes) {
  std::vector<std::uint8_t> miso(in_bytes);
  InCollector c{miso, 0, 0, std::chrono::steady_clock::now()};
  std::optional<Error> failure;
  BulkStream s;
  s.out_endpoint = ep_out_;
  s.in_endpoint = ep_in_;
  s.out = cmd;
  s.out_chunk = 16 * 1024;
  // Each IN transfer ends at the chip's next short packet; 32 packets keep a full-speed link busy
  // and four in flight keep the chip's RX FIFO from ever stalling the MPSSE for a host round trip.
  s.in_transfer_bytes = std::size_t{packet_size_} * 32;
  s.in_queue_depth = 4;
  s.timeout_ms = cfg_.timeout_ms;
  const BulkStreamResult res = dev_.bulk_stream(s, [&](std::span<const std::uint8_t> transfer) {
    ++stats_.usb_in_transfers;
    stats_.usb_bytes_in += transfer.size();
    auto r = collect_in(c, transfer);
    if (!r) {
      failure = r.error();
      return StreamStep::Abort;
    }
    return *r ? StreamStep::Done : StreamStep::More;
  });
  if (res.status == UsbStatus::NotSupported && res.out_transferred == 0 && res.in_transfers == 0) {
    stream_supported_ = false;
    return std::optional<std::vector<std::uint8_t>>{};
  }
  ++stats_.round_trips;
  ++stats_.streamed_reads;
  stats_.usb_out_transfers += res.out_transfers;
  stats_.usb_bytes_out += res.out_transferred;
  if (failure) return *failure;
  if (!res.ok())
    return usb_error(res.status, where() + ": streamed read (" + std::to_string(c.got) + " of " + std::to_string(in_bytes) +
                                     " bytes received, " + std::to_string(res.out_transferred) + " of " +
                                     std::to_string(cmd.size()) + " command bytes sent)");
  if (c.got != in_bytes)  // the stream ended Ok only after our Done, so this is a device-layer bug
    return make_error(where() + ": stream ended with " + std::to_string(c.got) + " of " + std::to_string(in_bytes) + " bytes",
                      backends::kDeviceProtocol);
  return std::optional<std::vector<std::uint8_t>>{std::move(miso)};
}

std::vector<std::uint8_t> FtdiMpsseBridge::encode(std::span<const SpiWindow> windows) const {
  std::vector<std::uint8_t> cmd;
  const std::uint8_t duplex = cfg_.read_edge == ReadEdge::Rising ? kDuplexReadPos : kDuplexReadNeg;
  const std::vector<std::size_t> kNoWaits;
  for (const auto& w : windows) {
    // Without a wired BUSY pin the board backend does flow control itself; no 0x89 is sent.
    const std::vector<std::size_t>& waits = cfg_.busy_pin ? w.busy_waits : kNoWaits;
    cmd.insert(cmd.end(), {kSetBitsLow, static_cast<std::uint8_t>(idle_value_ & ~(1u << cfg_.cs_pin)), direction_});
    std::size_t off = 0;
    std::size_t next_wait = 0;
    const std::size_t max_chunk = w.capture_miso ? std::min(kMaxCommandBytes, fifo_ / 2) : kMaxCommandBytes;
    while (off < w.mosi.size() || next_wait < waits.size()) {
      while (next_wait < waits.size() && waits[next_wait] <= off) {
        cmd.push_back(kWaitGpiol1Low);
        ++next_wait;
      }
      if (off >= w.mosi.size()) break;
      std::size_t end = std::min(w.mosi.size(), off + max_chunk);
      if (next_wait < waits.size()) end = std::min(end, std::max(off + 1, waits[next_wait]));
      const std::size_t n = end - off;
      cmd.insert(cmd.end(), {w.capture_miso ? duplex : kWriteBytesNeg, static_cast<std::uint8_t>((n - 1) & 0xFF),
                             static_cast<std::uint8_t>((n - 1) >> 8)});
      cmd.insert(cmd.end(), w.mosi.begin() + static_cast<std::ptrdiff_t>(off), w.mosi.begin() + static_cast<std::ptrdiff_t>(end));
      off = end;
    }
    cmd.insert(cmd.end(), {kSetBitsLow, idle_value_, direction_});
  }
  return cmd;
}

Result<std::vector<std::uint8_t>> FtdiMpsseBridge::transfer(std::span<const SpiWindow> windows) {
  // Commands are grouped into rounds whose read bytes fit the RX FIFO; a round that reads ends
  // with SEND_IMMEDIATE, a write-only round ends with nothing (no round trip at all).
  std::vector<std::uint8_t> miso;
  std::size_t total_in = 0;
  for (const auto& w : windows) {
    if (w.capture_miso) total_in += w.mosi.size();
    stats_.spi_bits += 8 * w.mosi.size();
    if (cfg_.busy_pin) stats_.busy_waits += w.busy_waits.size();
  }
  std::vector<std::uint8_t> cmd = encode(windows);

  // More than one RX FIFO of reads: one stream instead of a round trip per FIFO-full.
  if (total_in > fifo_ && cfg_.stream_reads && stream_supported_) {
    cmd.push_back(kSendImmediate);
    auto streamed = stream_transfer(cmd, total_in);
    if (!streamed) return streamed.error();
    if (*streamed) return std::move(**streamed);
    cmd.pop_back();  // no asynchronous path on this device: synchronous rounds below
  }
  miso.reserve(total_in);

  // Walk the command stream to find round boundaries (only full-duplex commands produce IN bytes).
  std::size_t round_start = 0, round_in = 0, pos = 0;
  std::vector<std::uint8_t> out;
  auto flush_round = [&](std::size_t end) -> Result<void> {
    out.assign(cmd.begin() + static_cast<std::ptrdiff_t>(round_start), cmd.begin() + static_cast<std::ptrdiff_t>(end));
    if (round_in) out.push_back(kSendImmediate);
    if (auto r = write_all(out); !r) return r;
    if (round_in) {
      const std::size_t at = miso.size();
      miso.resize(at + round_in);
      if (auto r = read_exact(std::span<std::uint8_t>(miso).subspan(at)); !r) return r;
    }
    round_start = end;
    round_in = 0;
    return {};
  };
  while (pos < cmd.size()) {
    const std::uint8_t op = cmd[pos];
    std::size_t len = 1, in = 0;
    if (op == kSetBitsLow || op == kSetDivisor) {
      len = 3;
    } else if (op == kWriteBytesNeg || op == kDuplexReadPos || op == kDuplexReadNeg) {
      const std::size_t n = (std::size_t{cmd[pos + 1]} | std::size_t{cmd[pos + 2]} << 8) + 1;
      len = 3 + n;
      if (op != kWriteBytesNeg) in = n;
    }
    if (in && round_in + in > fifo_) {
      if (auto r = flush_round(pos); !r) return r.error();
    }
    round_in += in;
    pos += len;
  }
  if (round_start < cmd.size()) {
    if (auto r = flush_round(cmd.size()); !r) return r.error();
  }
  return miso;
}

}  // namespace gpubridge::usb
