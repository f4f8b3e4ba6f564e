#include "gpubridge/usb/hidapi_transport.hpp"

#include <hidapi/hidapi.h>

#include <cstdio>
#include <cwchar>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/usb/usb_errors.hpp"

namespace gpubridge::usb {
namespace {

std::string narrow(const wchar_t* w) {
  std::string s;
  if (!w) return s;
  for (; *w; ++w) s += (*w < 128) ? static_cast<char>(*w) : '?';
  return s;
}

class HidapiDevice final : public HidDevice {
 public:
  HidapiDevice(std::shared_ptr<HidapiContext> ctx, hid_device* h, HidDeviceInfo info)
      : ctx_(std::move(ctx)), h_(h), info_(std::move(info)) {}
  ~HidapiDevice() override { hid_close(h_); }
  const HidDeviceInfo& info() const override { return info_; }
  int write(std::span<const std::uint8_t> data) override { return hid_write(h_, data.data(), data.size()); }
  int read(std::span<std::uint8_t> data, int timeout_ms) override {
    return hid_read_timeout(h_, data.data(), data.size(), timeout_ms);
  }
  std::string last_error() const override { return narrow(hid_error(h_)); }

 private:
  std::shared_ptr<HidapiContext> ctx_;
  hid_device* h_;
  HidDeviceInfo info_;
};

}  // namespace

Result<std::shared_ptr<HidapiContext>> HidapiContext::create() {
  if (hid_init() != 0) return make_error("hidapi: hid_init failed", backends::kDeviceProtocol);
  return std::shared_ptr<HidapiContext>(new HidapiContext());
}

HidapiContext::~HidapiContext() { hid_exit(); }

std::vector<HidDeviceInfo> HidapiContext::enumerate(std::uint16_t vid, std::uint16_t pid) {
  std::vector<HidDeviceInfo> out;
  hid_device_info* list = hid_enumerate(vid, pid);
  for (auto* d = list; d; d = d->next) {
    HidDeviceInfo i;
    i.vid = d->vendor_id;
    i.pid = d->product_id;
    i.path = d->path ? d->path : "";
    i.serial = narrow(d->serial_number);
    i.product = narrow(d->product_string);
    out.push_back(std::move(i));
  }
  hid_free_enumeration(list);
  return out;
}

Result<std::unique_ptr<HidDevice>> HidapiContext::open(std::uint16_t vid, std::uint16_t pid, const std::string& serial) {
  char id[16];
  std::snprintf(id, sizeof id, "%04x:%04x", vid, pid);
  for (const auto& i : enumerate(vid, pid)) {
    if (!serial.empty() && i.serial != serial) continue;
    hid_device* h = hid_open_path(i.path.c_str());
    if (!h)
      return make_error(std::string("HID device ") + id + " at " + i.path + ": cannot open (no permission?); " +
                            std::string(kUdevHint),
                        backends::kDeviceProtocol);
    return std::unique_ptr<HidDevice>(std::make_unique<HidapiDevice>(shared_from_this(), h, i));
  }
  return make_error(std::string("no HID device ") + id + (serial.empty() ? "" : " with serial " + serial) +
                        " is attached; plug in the adapter",
                    backends::kDeviceGone);
}

}  // namespace gpubridge::usb
