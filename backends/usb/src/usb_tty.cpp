#include "gpubridge/usb/usb_tty.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>

namespace gpubridge::usb {
namespace {

namespace fs = std::filesystem;

// One sysfs attribute, trailing newline removed; empty when absent.
std::string attribute(const fs::path& file) {
  std::ifstream in(file);
  std::string s;
  std::getline(in, s);
  return s;
}

bool parse_hex(const std::string& s, unsigned long& out) {
  if (s.empty() || s.size() > 4 || s.find_first_not_of("0123456789abcdefABCDEF") != std::string::npos) return false;
  out = std::stoul(s, nullptr, 16);
  return true;
}

std::string hex4(std::uint16_t v) {
  char b[8];
  std::snprintf(b, sizeof b, "%04x", v);
  return b;
}

}  // namespace

std::vector<UsbTty> list_usb_ttys(const fs::path& sysfs, const fs::path& dev) {
  std::vector<UsbTty> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(sysfs / "class" / "tty", ec)) {
    const std::string name = e.path().filename().string();
    if (!name.starts_with("ttyUSB") && !name.starts_with("ttyACM")) continue;
    // class/tty/X/device is the usb-serial port (ttyUSB) or the USB interface (ttyACM); the
    // interface directory has bInterfaceNumber, the device above it idVendor/idProduct.
    std::error_code ec2;
    fs::path at = fs::canonical(e.path() / "device", ec2);
    if (ec2) continue;
    UsbTty t;
    t.path = (dev / name).string();
    t.driver = fs::canonical(e.path() / "device" / "driver", ec2).filename().string();
    for (int depth = 0; depth < 4 && !at.empty() && at != at.root_path(); ++depth, at = at.parent_path()) {
      unsigned long v = 0;
      if (t.interface < 0 && parse_hex(attribute(at / "bInterfaceNumber"), v)) t.interface = static_cast<int>(v);
      unsigned long vid = 0, pid = 0;
      if (parse_hex(attribute(at / "idVendor"), vid) && parse_hex(attribute(at / "idProduct"), pid)) {
        t.vid = static_cast<std::uint16_t>(vid);
        t.pid = static_cast<std::uint16_t>(pid);
        t.serial = attribute(at / "serial");
        out.push_back(std::move(t));
        break;
      }
    }
  }
  std::sort(out.begin(), out.end(), [](const UsbTty& a, const UsbTty& b) { return a.path < b.path; });
  return out;
}

Result<std::string> find_usb_tty(std::uint16_t vid, std::uint16_t pid, int interface, const std::string& serial,
                                 const fs::path& sysfs, const fs::path& dev) {
  const auto ttys = list_usb_ttys(sysfs, dev);
  std::string seen;
  for (const auto& t : ttys) {
    seen += (seen.empty() ? "" : ", ") + t.path + " (" + hex4(t.vid) + ":" + hex4(t.pid) + " interface " + std::to_string(t.interface) + ")";
    if (t.vid == vid && t.pid == pid && t.interface == interface && (serial.empty() || t.serial == serial)) return t.path;
  }
  std::string want = hex4(vid) + ":" + hex4(pid) + " interface " + std::to_string(interface) + (serial.empty() ? "" : " serial " + serial);
  return make_error("no USB serial port for " + want + " (" + (seen.empty() ? "no ttyUSB/ttyACM ports at all" : "attached: " + seen) +
                    "); plug the adapter in, check `gpubridge probe`, or name the port with --tty (a profile's uart.tty)");
}

}  // namespace gpubridge::usb
