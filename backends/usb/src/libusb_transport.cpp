#include "gpubridge/usb/libusb_transport.hpp"

#include <libusb.h>

#include <cstdio>
#include <map>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/usb/usb_errors.hpp"
#include "libusb_status.hpp"
#include "libusb_stream.hpp"

namespace gpubridge::usb {

struct LibusbContext::Raw {
  libusb_context* ctx = nullptr;
  ~Raw() {
    if (ctx) libusb_exit(ctx);
  }
};

namespace {

std::string port_path_of(libusb_device* dev) {
  std::uint8_t ports[8];
  const int n = libusb_get_port_numbers(dev, ports, 8);
  std::string s = std::to_string(libusb_get_bus_number(dev));
  for (int i = 0; i < n; ++i) s += (i == 0 ? "-" : ".") + std::to_string(ports[i]);
  return s;
}

std::string string_descriptor(libusb_device_handle* h, std::uint8_t index) {
  if (!index || !h) return "";
  unsigned char buf[256];
  const int n = libusb_get_string_descriptor_ascii(h, index, buf, sizeof buf);
  return n > 0 ? std::string(reinterpret_cast<char*>(buf), static_cast<std::size_t>(n)) : "";
}

class LibusbDevice final : public UsbDevice {
 public:
  LibusbDevice(std::shared_ptr<LibusbContext::Raw> ctx, libusb_device_handle* h, UsbDeviceInfo info)
      : ctx_(std::move(ctx)), h_(h), info_(std::move(info)) {
    libusb_config_descriptor* cfg = nullptr;
    if (libusb_get_active_config_descriptor(libusb_get_device(h_), &cfg) == 0) {
      for (int i = 0; i < cfg->bNumInterfaces; ++i)
        for (int a = 0; a < cfg->interface[i].num_altsetting; ++a) {
          const auto& alt = cfg->interface[i].altsetting[a];
          for (int e = 0; e < alt.bNumEndpoints; ++e)
            packet_[alt.endpoint[e].bEndpointAddress] = alt.endpoint[e].wMaxPacketSize;
        }
      libusb_free_config_descriptor(cfg);
    }
  }
  ~LibusbDevice() override { libusb_close(h_); }

  const UsbDeviceInfo& info() const override { return info_; }
  UsbStatus detach_kernel_driver(int i) override {
    const int active = libusb_kernel_driver_active(h_, i);
    if (active == 0) return UsbStatus::NotFound;
    if (active < 0) return status_of(active);
    return status_of(libusb_detach_kernel_driver(h_, i));
  }
  UsbStatus claim_interface(int i) override { return status_of(libusb_claim_interface(h_, i)); }
  UsbStatus release_interface(int i) override { return status_of(libusb_release_interface(h_, i)); }
  UsbIo control_out(std::uint8_t rt, std::uint8_t req, std::uint16_t value, std::uint16_t index,
                    std::span<const std::uint8_t> data, unsigned timeout_ms) override {
    const int rc = libusb_control_transfer(h_, rt, req, value, index, const_cast<unsigned char*>(data.data()),
                                           static_cast<std::uint16_t>(data.size()), timeout_ms);
    return rc < 0 ? UsbIo{status_of(rc), 0} : UsbIo{UsbStatus::Ok, static_cast<std::size_t>(rc)};
  }
  UsbIo control_in(std::uint8_t rt, std::uint8_t req, std::uint16_t value, std::uint16_t index, std::span<std::uint8_t> data,
                   unsigned timeout_ms) override {
    const int rc = libusb_control_transfer(h_, rt, req, value, index, data.data(), static_cast<std::uint16_t>(data.size()), timeout_ms);
    return rc < 0 ? UsbIo{status_of(rc), 0} : UsbIo{UsbStatus::Ok, static_cast<std::size_t>(rc)};
  }
  UsbIo bulk_out(std::uint8_t ep, std::span<const std::uint8_t> data, unsigned timeout_ms) override {
    int done = 0;
    const int rc = libusb_bulk_transfer(h_, ep, const_cast<unsigned char*>(data.data()), static_cast<int>(data.size()), &done, timeout_ms);
    return {status_of(rc), static_cast<std::size_t>(done)};
  }
  UsbIo bulk_in(std::uint8_t ep, std::span<std::uint8_t> data, unsigned timeout_ms) override {
    int done = 0;
    const int rc = libusb_bulk_transfer(h_, ep, data.data(), static_cast<int>(data.size()), &done, timeout_ms);
    return {status_of(rc), static_cast<std::size_t>(done)};
  }
  UsbStatus clear_halt(std::uint8_t ep) override { return status_of(libusb_clear_halt(h_, ep)); }
  BulkStreamResult bulk_stream(const BulkStream& s, const InSink& on_in) override {
    return run_libusb_stream(ctx_->ctx, h_, s, on_in);
  }
  std::uint16_t max_packet_size(std::uint8_t ep) const override {
    auto it = packet_.find(ep);
    return it == packet_.end() ? 0 : it->second;
  }

 private:
  std::shared_ptr<LibusbContext::Raw> ctx_;  // outlives the handle
  libusb_device_handle* h_;
  UsbDeviceInfo info_;
  std::map<std::uint8_t, std::uint16_t> packet_;
};

UsbDeviceInfo basic_info(libusb_device* dev, const libusb_device_descriptor& d) {
  UsbDeviceInfo i;
  i.vid = d.idVendor;
  i.pid = d.idProduct;
  i.bcd_device = d.bcdDevice;
  i.bus = libusb_get_bus_number(dev);
  i.address = libusb_get_device_address(dev);
  i.port_path = port_path_of(dev);
  i.high_speed = libusb_get_device_speed(dev) >= LIBUSB_SPEED_HIGH;
  return i;
}

}  // namespace

Result<std::shared_ptr<LibusbContext>> LibusbContext::create() {
  auto raw = std::make_shared<Raw>();
  const int rc = libusb_init(&raw->ctx);
  if (rc != 0) return usb_error(status_of(rc), "libusb_init");
  std::shared_ptr<LibusbContext> c(new LibusbContext());
  c->raw_ = std::move(raw);
  return c;
}

LibusbContext::~LibusbContext() = default;

Result<std::vector<FoundDevice>> LibusbContext::enumerate(const std::vector<std::pair<std::uint16_t, std::uint16_t>>& ids) {
  libusb_device** list = nullptr;
  const ssize_t n = libusb_get_device_list(raw_->ctx, &list);
  if (n < 0) return usb_error(status_of(static_cast<int>(n)), "list USB devices");
  std::vector<FoundDevice> out;
  for (ssize_t k = 0; k < n; ++k) {
    libusb_device_descriptor d{};
    if (libusb_get_device_descriptor(list[k], &d) != 0) continue;
    bool wanted = false;
    for (const auto& [v, p] : ids) wanted |= d.idVendor == v && d.idProduct == p;
    if (!wanted) continue;
    FoundDevice f;
    f.info = basic_info(list[k], d);
    libusb_device_handle* h = nullptr;
    const int rc = libusb_open(list[k], &h);
    if (rc == 0) {
      f.accessible = true;
      f.info.serial = string_descriptor(h, d.iSerialNumber);
      f.info.manufacturer = string_descriptor(h, d.iManufacturer);
      f.info.product = string_descriptor(h, d.iProduct);
      if (libusb_kernel_driver_active(h, 0) == 1) f.problem = "kernel driver attached (it will be detached on open)";
      libusb_close(h);
    } else {
      f.problem = usb_error(status_of(rc), "open").message;
    }
    out.push_back(std::move(f));
  }
  libusb_free_device_list(list, 1);
  return out;
}

Result<std::unique_ptr<UsbDevice>> LibusbContext::open(const UsbMatch& m) {
  auto found = enumerate({{m.vid, m.pid}});
  if (!found) return found.error();
  const FoundDevice* pick = nullptr;
  for (const auto& f : *found) {
    if (!m.serial.empty() && f.info.serial != m.serial) continue;
    if (!m.port_path.empty() && f.info.port_path != m.port_path) continue;
    pick = &f;
    break;
  }
  char id[16];
  std::snprintf(id, sizeof id, "%04x:%04x", m.vid, m.pid);
  if (!pick) {
    std::string msg = std::string("no USB device ") + id;
    if (!m.serial.empty()) msg += " with serial " + m.serial;
    if (!m.port_path.empty()) msg += " at port " + m.port_path;
    msg += found->empty() ? " is attached; plug in the adapter (gpubridge probe lists what is connected)"
                          : " among the " + std::to_string(found->size()) + " attached (gpubridge probe lists them)";
    return make_error(msg, backends::kDeviceGone);
  }
  if (!pick->accessible) return make_error(std::string(id) + " at port " + pick->info.port_path + ": " + pick->problem,
                                           backends::kDeviceProtocol);
  // Re-find the libusb_device by port path (the address may have changed since enumeration).
  libusb_device** list = nullptr;
  const ssize_t n = libusb_get_device_list(raw_->ctx, &list);
  if (n < 0) return usb_error(status_of(static_cast<int>(n)), "list USB devices");
  libusb_device_handle* h = nullptr;
  int rc = LIBUSB_ERROR_NO_DEVICE;
  for (ssize_t k = 0; k < n && !h; ++k) {
    libusb_device_descriptor d{};
    if (libusb_get_device_descriptor(list[k], &d) != 0 || d.idVendor != m.vid || d.idProduct != m.pid) continue;
    if (port_path_of(list[k]) != pick->info.port_path) continue;
    rc = libusb_open(list[k], &h);
  }
  libusb_free_device_list(list, 1);
  if (!h) return usb_error(status_of(rc), std::string("open ") + id + " at port " + pick->info.port_path);
  return std::unique_ptr<UsbDevice>(std::make_unique<LibusbDevice>(raw_, h, pick->info));
}

}  // namespace gpubridge::usb
