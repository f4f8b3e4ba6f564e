// Fuzzes the four USB-SPI bridge drivers against a transport that answers from the fuzz input:
// every status, every transferred count and every byte a chip sends back is a decision of the
// script (fuzz_input.hpp), including counts larger than the buffer that was offered.
//
// Input layout: [chip] [options] [cs] [packet size] [clock lo] [clock hi], then the script. The
// harness opens the bridge, then runs up to four transfers whose windows (count, size, capture,
// BUSY waits) also come from the script; after a failed transfer it calls recover(), as the
// board backend does. Each transport call reads a status byte first:
//   low nibble 0..9 = success (0..8 for statuses of bulk/control/HID transfers), others = a
//   failure (timeout, stall, unplug, ...); bit 6 = a 16-bit length follows instead of 8 bits;
//   bit 7 = report more bytes transferred than the buffer holds (a lying transport).
// IN transfers then read the length and that many payload bytes. When the script runs out every
// call fails as an unplugged device, so each run ends.
// Properties: no crash/UB/leak/hang; every failure is an Error with a message and a BackendError
// code (100..103); a successful transfer returns exactly one MISO byte per captured MOSI byte; an
// open, transfer or recover during which an IN transfer or HID read reported more bytes than its
// buffer holds does not succeed (the count is a transport fault, not data).
#include <array>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "fuzz_check.hpp"
#include "fuzz_input.hpp"
#include "gpubridge/backends/backend.hpp"
#include "gpubridge/usb/ch341a.hpp"
#include "gpubridge/usb/cp2130.hpp"
#include "gpubridge/usb/ftdi_mpsse.hpp"
#include "gpubridge/usb/hid_device.hpp"
#include "gpubridge/usb/mcp2210.hpp"
#include "gpubridge/usb/usb_device.hpp"

namespace {

using namespace gpubridge;
using namespace gpubridge::usb;
using gpubridge::fuzz::FuzzInput;

constexpr UsbStatus kTransferFailures[] = {UsbStatus::Timeout, UsbStatus::Pipe,     UsbStatus::NoDevice,
                                           UsbStatus::Io,      UsbStatus::Overflow, UsbStatus::Busy,
                                           UsbStatus::Other};
constexpr UsbStatus kSetupFailures[] = {UsbStatus::NotFound, UsbStatus::NotSupported, UsbStatus::Busy,
                                        UsbStatus::Access,   UsbStatus::NoDevice,     UsbStatus::Pipe};

struct Decision {
  UsbStatus status = UsbStatus::NoDevice;
  bool long_length = false;
  bool lie = false;
};

Decision transfer_decision(FuzzInput& in) {
  if (in.exhausted()) return {};
  const std::uint8_t s = in.byte();
  const unsigned kind = s & 0x0F;
  return {kind <= 8 ? UsbStatus::Ok : kTransferFailures[kind - 9], (s & 0x40) != 0, (s & 0x80) != 0};
}

UsbStatus setup_status(FuzzInput& in) {
  if (in.exhausted()) return UsbStatus::NoDevice;
  const unsigned kind = in.byte() & 0x0F;
  return kind <= 9 ? UsbStatus::Ok : kSetupFailures[kind - 10];
}

// What the script has done to the driver so far.
struct Script {
  FuzzInput in;
  bool lied_in = false;  // an IN transfer or HID read reported more bytes than its buffer
};

// Bytes "received": the length decision, then that many payload bytes (at most the buffer).
std::size_t receive(Script& sc, const Decision& d, std::span<std::uint8_t> buf) {
  const std::size_t wanted = d.long_length ? sc.in.u16() : sc.in.byte();
  const std::size_t n = std::min(wanted, buf.size());
  sc.in.fill(buf.first(n));
  if (!d.lie) return n;
  if (d.status == UsbStatus::Ok) sc.lied_in = true;  // a failed transfer's count is not used
  return buf.size() + 1 + wanted;
}

class ScriptedUsbDevice final : public UsbDevice {
 public:
  ScriptedUsbDevice(Script& sc, UsbDeviceInfo info, std::uint16_t packet)
      : sc_(sc), in_(sc.in), info_(std::move(info)), packet_(packet) {}
  const UsbDeviceInfo& info() const override { return info_; }
  UsbStatus detach_kernel_driver(int) override { return setup_status(in_); }
  UsbStatus claim_interface(int) override { return setup_status(in_); }
  UsbStatus release_interface(int) override { return setup_status(in_); }
  UsbStatus clear_halt(std::uint8_t) override { return setup_status(in_); }
  std::uint16_t max_packet_size(std::uint8_t) const override { return packet_; }
  UsbIo control_out(std::uint8_t, std::uint8_t, std::uint16_t, std::uint16_t, std::span<const std::uint8_t> data,
                    unsigned) override {
    return out(data.size());
  }
  UsbIo bulk_out(std::uint8_t, std::span<const std::uint8_t> data, unsigned) override { return out(data.size()); }
  UsbIo control_in(std::uint8_t, std::uint8_t, std::uint16_t, std::uint16_t, std::span<std::uint8_t> data,
                   unsigned) override {
    return in(data);
  }
  UsbIo bulk_in(std::uint8_t, std::span<std::uint8_t> data, unsigned) override { return in(data); }
  // The asynchronous stream (FTDI reads beyond the RX FIFO): a start decision (a failure before
  // anything moved, or "Other" = no asynchronous path), then one decision + payload per completed
  // IN transfer until the consumer says Done or Abort, a transfer fails or the script ends.
  BulkStreamResult bulk_stream(const BulkStream& s, const InSink& on_in) override {
    const Decision start = transfer_decision(in_);
    if (start.status == UsbStatus::Other) return {UsbStatus::NotSupported, 0, 0, 0};
    if (start.status != UsbStatus::Ok) return {start.status, in_.byte() % (s.out.size() + 1), 1, 0};
    BulkStreamResult res{UsbStatus::Ok, s.out.size(), (s.out.size() + s.out_chunk - 1) / std::max<std::size_t>(s.out_chunk, 1), 0};
    std::vector<std::uint8_t> buf(s.in_transfer_bytes);
    while (true) {
      const Decision d = transfer_decision(in_);
      if (d.status != UsbStatus::Ok) {
        res.status = d.status;
        return res;
      }
      const std::size_t wanted = d.long_length ? in_.u16() : in_.byte();
      const std::size_t n = std::min(wanted, buf.size());
      in_.fill(std::span(buf).first(n));
      ++res.in_transfers;
      if (on_in(std::span<const std::uint8_t>(buf).first(n)) != StreamStep::More) return res;
    }
  }

 private:
  // A successful OUT moves every byte (libusb semantics); a failed one some of them.
  UsbIo out(std::size_t size) {
    const Decision d = transfer_decision(in_);
    if (d.status == UsbStatus::Ok) return {UsbStatus::Ok, d.lie ? size + 1 : size};
    return {d.status, in_.byte() % (size + 1)};
  }
  UsbIo in(std::span<std::uint8_t> buf) {
    const Decision d = transfer_decision(in_);
    if (d.status == UsbStatus::NoDevice && in_.exhausted()) return {UsbStatus::NoDevice, 0};
    return {d.status, receive(sc_, d, buf)};  // a timeout may still have moved bytes
  }

  Script& sc_;
  FuzzInput& in_;
  UsbDeviceInfo info_;
  std::uint16_t packet_;
};

class ScriptedHidDevice final : public HidDevice {
 public:
  explicit ScriptedHidDevice(Script& sc) : sc_(sc), in_(sc.in) { info_.vid = 0x04D8, info_.pid = 0x00DE; }
  const HidDeviceInfo& info() const override { return info_; }
  int write(std::span<const std::uint8_t> data) override {
    const Decision d = transfer_decision(in_);
    return d.status == UsbStatus::Ok ? static_cast<int>(data.size()) : -1;
  }
  int read(std::span<std::uint8_t> data, int) override {
    const Decision d = transfer_decision(in_);
    if (d.status != UsbStatus::Ok) return -1;
    return static_cast<int>(receive(sc_, d, data));  // 0 = the read timed out
  }
  std::string last_error() const override { return "scripted HID failure"; }

 private:
  Script& sc_;
  FuzzInput& in_;
  HidDeviceInfo info_;
};

UsbDeviceInfo device_info(std::uint16_t vid, std::uint16_t pid, std::uint16_t bcd = 0) {
  UsbDeviceInfo info;
  info.vid = vid;
  info.pid = pid;
  info.bcd_device = bcd;
  info.port_path = "1-2";
  return info;
}

// FUZZ_VERBOSE=1 prints every error (for reading what a reproducer does).
void check_error(const Error& e) {
  static const bool verbose = std::getenv("FUZZ_VERBOSE") != nullptr;
  if (verbose) std::fprintf(stderr, "error %d: %s\n", e.code, e.message.c_str());
  FUZZ_CHECK(!e.message.empty());
  FUZZ_CHECK(e.code >= backends::kDeviceGone && e.code <= backends::kBadRequest);
}

// Up to four transfers with windows chosen by the script; recover() after each failure.
void exercise(SpiBridge& bridge, Script& sc) {
  FuzzInput& in = sc.in;
  std::vector<std::uint8_t> mosi(8192);
  for (std::size_t i = 0; i < mosi.size(); ++i) mosi[i] = static_cast<std::uint8_t>(i * 7 + 1);
  for (int round = 0; round < 4 && !in.exhausted(); ++round) {
    const std::uint8_t plan = in.byte();
    if (plan == 0xFF) {  // a clock change instead of a transfer
      if (auto r = bridge.set_clock(std::uint32_t{in.u16()} * 500); !r) check_error(r.error());
      continue;
    }
    std::vector<SpiWindow> windows(1 + plan % 3);
    std::size_t captured = 0;
    for (auto& w : windows) {
      const std::size_t n = in.u16() % (mosi.size() + 1);
      w.mosi = std::span<const std::uint8_t>(mosi).first(n);
      w.capture_miso = (in.byte() & 1) != 0;
      for (unsigned k = in.byte() % 4, at = 0; k > 0; --k) w.busy_waits.push_back(at += in.byte());
      if (w.capture_miso) captured += n;
    }
    sc.lied_in = false;
    auto miso = bridge.transfer(windows);
    FUZZ_CHECK(!(miso && sc.lied_in));
    if (miso) {
      if (std::getenv("FUZZ_VERBOSE")) std::fprintf(stderr, "transfer ok: %zu MISO bytes\n", miso->size());
      FUZZ_CHECK(miso->size() == captured);
      continue;
    }
    check_error(miso.error());
    sc.lied_in = false;
    auto r = bridge.recover();
    FUZZ_CHECK(!(r && sc.lied_in));
    if (!r) check_error(r.error());
  }
}

template <class Bridge>
void run(Result<std::unique_ptr<Bridge>> opened, Script& sc) {
  if (!opened) {
    check_error(opened.error());
    return;
  }
  FUZZ_CHECK(!sc.lied_in);
  exercise(**opened, sc);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Script sc{FuzzInput(data, size)};
  FuzzInput& in = sc.in;
  const unsigned chip = in.byte() % 4;
  const std::uint8_t options = in.byte();
  const std::uint8_t cs = in.byte();
  const std::uint8_t packet_choice = in.byte();
  const std::uint32_t clock_hz = std::uint32_t{in.u16()} * 1000;
  switch (chip) {
    case 0: {
      static constexpr std::uint16_t kBcd[] = {0x0900, 0x0700, 0x0800, 0x3600, 0x0600};
      static constexpr std::uint16_t kPackets[] = {512, 64, 3, 2, 0, 8, 16, 1024};
      FtdiConfig cfg;
      cfg.channel = (options >> 3) & 1;
      cfg.busy_pin = (options >> 4) & 1;
      cfg.read_edge = (options >> 5) & 1 ? ReadEdge::Falling : ReadEdge::Rising;
      cfg.latency_ms = static_cast<std::uint8_t>(1 + (options >> 6));
      cfg.cs_pin = static_cast<std::uint8_t>(cs % 9);
      cfg.clock_hz = clock_hz;
      ScriptedUsbDevice dev(sc, device_info(0x0403, 0x6014, kBcd[options % 5]), kPackets[packet_choice % 8]);
      run(FtdiMpsseBridge::open(dev, cfg), sc);
      break;
    }
    case 1: {
      ScriptedUsbDevice dev(sc, device_info(0x1A86, 0x5512), 32);
      run(Ch341aBridge::open(dev), sc);
      break;
    }
    case 2: {
      ScriptedHidDevice dev(sc);
      run(Mcp2210Bridge::open(dev, cs % 10, clock_hz), sc);
      break;
    }
    case 3: {
      ScriptedUsbDevice dev(sc, device_info(0x10C4, 0x87A0), 64);
      run(Cp2130Bridge::open(dev, cs % 12, clock_hz), sc);
      break;
    }
  }
  return 0;
}
