#pragma once
// USB serial ports (USB-UART adapters: FTDI, CH340, CP210x, CDC-ACM) as the kernel made them:
// /dev/ttyUSB* and /dev/ttyACM*, with the USB ids and interface they belong to, read from sysfs.
// A board profile names its adapter by USB ids (configs/boards/icebreaker-dmc1.json); the kernel
// numbers ttys in plug order, so the port is looked up rather than written into the profile.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "gpubridge/common/result.hpp"

namespace gpubridge::usb {

struct UsbTty {
  std::string path;        // /dev/ttyUSB1
  std::uint16_t vid = 0, pid = 0;
  int interface = -1;      // bInterfaceNumber (FT2232H channel B = 1)
  std::string serial;      // the USB device's serial string, if it has one
  std::string driver;      // ftdi_sio, ch341, cp210x, cdc_acm, ...
};

// Every ttyUSB*/ttyACM* under sysfs/class/tty that sits on a USB device, in name order. The roots
// are parameters so tests can hand it a recorded sysfs tree.
std::vector<UsbTty> list_usb_ttys(const std::filesystem::path& sysfs = "/sys", const std::filesystem::path& dev = "/dev");

// The port of the adapter with these ids (and serial, when not empty); errors say what is attached.
Result<std::string> find_usb_tty(std::uint16_t vid, std::uint16_t pid, int interface, const std::string& serial,
                                 const std::filesystem::path& sysfs = "/sys", const std::filesystem::path& dev = "/dev");

}  // namespace gpubridge::usb
