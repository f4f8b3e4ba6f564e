#include "gpubridge/dmc1/serial_link.hpp"

#include <termios.h>

#include <cerrno>
#include <cstring>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/serial_port.hpp>
#include <boost/asio/write.hpp>

namespace gpubridge::dmc1 {

namespace asio = boost::asio;

struct SerialLink::Port {
  asio::io_context io;
  asio::serial_port port{io};
};

namespace {

// Bytes per write: a cancel takes effect within one chunk (about 45 ms at 115,200 baud).
constexpr std::size_t kWordsPerChunk = 64;

Error open_error(const std::string& path, const boost::system::error_code& ec) {
  namespace errc = boost::system::errc;
  if (ec == errc::no_such_file_or_directory)
    return make_error(path + ": no such serial port; is the USB-UART plugged in? `gpubridge probe` lists the USB serial ports");
  if (ec == errc::permission_denied)
    return make_error(path + ": permission denied; serial ports belong to the dialout group: sudo usermod -aG dialout $USER, "
                             "then log in again");
  if (ec == errc::device_or_resource_busy)
    return make_error(path + ": busy; another program holds the port (a serial terminal, ModemManager?)");
  if (ec == errc::inappropriate_io_control_operation)
    return make_error(path + ": not a serial port (the terminal settings cannot be set)");
  return make_error(path + ": cannot open the serial port: " + ec.message());
}

}  // namespace

SerialLink::SerialLink(std::unique_ptr<Port> port, std::string path, unsigned baud)
    : port_(std::move(port)), path_(std::move(path)), baud_(baud) {}

SerialLink::~SerialLink() = default;

Result<std::unique_ptr<SerialLink>> SerialLink::open(const std::string& path, unsigned baud) {
  auto port = std::make_unique<Port>();
  boost::system::error_code ec;
  port->port.open(path, ec);  // Asio sets raw mode: no echo, no line editing, no output processing
  if (ec) return open_error(path, ec);
  using base = asio::serial_port_base;
  port->port.set_option(base::baud_rate(baud), ec);
  if (ec) return make_error(path + ": the port does not take " + std::to_string(baud) + " baud (" + ec.message() + ")");
  port->port.set_option(base::character_size(8), ec);
  if (!ec) port->port.set_option(base::parity(base::parity::none), ec);
  if (!ec) port->port.set_option(base::stop_bits(base::stop_bits::one), ec);
  if (!ec) port->port.set_option(base::flow_control(base::flow_control::none), ec);  // the SOC has no RTS/CTS
  if (ec) return make_error(path + ": cannot set 8N1 without flow control: " + ec.message());
  return std::unique_ptr<SerialLink>(new SerialLink(std::move(port), path, baud));
}

Result<void> SerialLink::write(std::span<const std::uint8_t> bytes) {
  boost::system::error_code ec;
  const std::size_t n = asio::write(port_->port, asio::buffer(bytes.data(), bytes.size()), ec);
  stats_.bytes += n;
  if (ec)
    return make_error(path_ + ": write failed after " + std::to_string(stats_.bytes) + " bytes (" + ec.message() +
                      "); if the adapter was unplugged mid-command, press the board's reset button before streaming again");
  return {};
}

Result<void> SerialLink::send(std::span<const std::uint64_t> words) {
  std::vector<std::uint8_t> bytes;
  bytes.reserve(kWordsPerChunk * 8 + 2);
  for (std::size_t at = 0; at < words.size(); at += kWordsPerChunk) {
    if (cancel_ && cancel_->load(std::memory_order_relaxed))
      return make_error(path_ + ": cancelled after " + std::to_string(stats_.words) + " words (at a word boundary)", kSerialCancelled);
    bytes.clear();
    const auto chunk = words.subspan(at, std::min(kWordsPerChunk, words.size() - at));
    framer_.commands(chunk, bytes);
    if (auto r = write(bytes); !r) return r;
    stats_.words += bytes.size() / 8;  // the 2-byte opening is not a word
  }
  return {};
}

Result<void> SerialLink::send_screen(const ScreenCommand& c) {
  std::vector<std::uint8_t> bytes;
  framer_.screen(c, bytes);
  if (auto r = write(bytes); !r) return r;
  stats_.words += bytes.size() / 8;  // escape and screen word (and a no-op arming word right after the opening)
  return {};
}

Result<void> SerialLink::drain() {
  if (::tcdrain(port_->port.native_handle()) != 0)
    return make_error(path_ + ": waiting for the bytes to leave failed: " + std::string(std::strerror(errno)));
  return {};
}

}  // namespace gpubridge::dmc1
