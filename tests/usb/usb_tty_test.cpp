// USB serial ports from sysfs, on a tree laid out as Linux lays it out: class/tty/ttyUSBn links to
// the usb-serial port under the USB interface (ftdi_sio, ch341, cp210x); class/tty/ttyACMn links
// to the interface itself (cdc_acm); ttyS ports are not USB. And the UART board profiles that name
// these adapters (configs/boards/icebreaker-dmc1.json).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "gpubridge/usb/board_profile.hpp"
#include "gpubridge/usb/usb_tty.hpp"

namespace gpubridge::usb {
namespace {

namespace fs = std::filesystem;

class FakeSysfs {
 public:
  FakeSysfs() : root_(fs::temp_directory_path() / ("gpubridge-sysfs-" + std::to_string(::getpid()))) {
    fs::create_directories(root_ / "class" / "tty");
    fs::create_directories(root_ / "bus" / "usb-serial" / "drivers");
  }
  ~FakeSysfs() { fs::remove_all(root_); }
  const fs::path& root() const { return root_; }

  // A USB device with one interface holding a tty; `port_dir` is whether the driver puts a
  // usb-serial port directory between the interface and the tty (ttyUSB) or not (ttyACM).
  void add(const std::string& tty, const std::string& usb_dev, const char* vid, const char* pid, const char* serial, int interface,
           const std::string& driver, bool port_dir) {
    const fs::path dev = root_ / "devices" / "pci0000:00" / "usb1" / usb_dev;
    write(dev / "idVendor", vid);
    write(dev / "idProduct", pid);
    if (serial) write(dev / "serial", serial);
    char ifname[16];
    std::snprintf(ifname, sizeof ifname, ":1.%d", interface);
    const fs::path intf = dev / (usb_dev + ifname);
    char num[8];
    std::snprintf(num, sizeof num, "%02x", interface);
    write(intf / "bInterfaceNumber", num);
    const fs::path device = port_dir ? intf / tty : intf;
    fs::create_directories(device / "tty" / tty);
    fs::create_directories(root_ / "bus" / "usb-serial" / "drivers" / driver);
    fs::create_directory_symlink(root_ / "bus" / "usb-serial" / "drivers" / driver, device / "driver");
    fs::create_directory_symlink(device / "tty" / tty, root_ / "class" / "tty" / tty);
    fs::create_directory_symlink(device, device / "tty" / tty / "device");
  }
  void add_platform_tty(const std::string& tty) {
    const fs::path device = root_ / "devices" / "platform" / "serial8250";
    fs::create_directories(device / "tty" / tty);
    fs::create_directory_symlink(device / "tty" / tty, root_ / "class" / "tty" / tty);
    fs::create_directory_symlink(device, device / "tty" / tty / "device");
  }

 private:
  static void write(const fs::path& file, const std::string& text) {
    fs::create_directories(file.parent_path());
    std::ofstream(file) << text << "\n";
  }
  fs::path root_;
};

TEST(UsbTty, ListsUsbSerialPortsWithTheirInterface) {
  FakeSysfs sys;
  sys.add("ttyUSB0", "1-1", "0403", "6010", "ICEBRK01", 0, "ftdi_sio", true);  // iCEBreaker channel A (when not claimed by libusb)
  sys.add("ttyUSB1", "1-1", "0403", "6010", "ICEBRK01", 1, "ftdi_sio", true);  // channel B: the UART
  sys.add("ttyUSB2", "1-2", "1a86", "7523", nullptr, 0, "ch341", true);
  sys.add("ttyACM0", "1-3", "2e8a", "000a", "E66038B7", 0, "cdc_acm", false);
  sys.add_platform_tty("ttyS0");
  const auto ttys = list_usb_ttys(sys.root(), "/dev");
  ASSERT_EQ(ttys.size(), 4u);
  EXPECT_EQ(ttys[0].path, "/dev/ttyACM0");
  EXPECT_EQ(ttys[0].vid, 0x2e8a);
  EXPECT_EQ(ttys[0].interface, 0);
  EXPECT_EQ(ttys[0].driver, "cdc_acm");
  EXPECT_EQ(ttys[2].path, "/dev/ttyUSB1");
  EXPECT_EQ(ttys[2].pid, 0x6010);
  EXPECT_EQ(ttys[2].interface, 1);
  EXPECT_EQ(ttys[2].serial, "ICEBRK01");
  EXPECT_EQ(ttys[2].driver, "ftdi_sio");
  EXPECT_EQ(ttys[3].serial, "");  // the CH340 has no serial string

  auto b = find_usb_tty(0x0403, 0x6010, 1, "", sys.root(), "/dev");
  ASSERT_TRUE(b) << b.error().message;
  EXPECT_EQ(*b, "/dev/ttyUSB1");
  EXPECT_TRUE(find_usb_tty(0x0403, 0x6010, 1, "ICEBRK01", sys.root(), "/dev"));
  auto wrong_serial = find_usb_tty(0x0403, 0x6010, 1, "OTHER", sys.root(), "/dev");
  ASSERT_FALSE(wrong_serial);
  EXPECT_NE(wrong_serial.error().message.find("attached: /dev/ttyACM0 (2e8a:000a interface 0)"), std::string::npos)
      << wrong_serial.error().message;
  EXPECT_NE(wrong_serial.error().message.find("--tty"), std::string::npos);
}

TEST(UsbTty, NoPortsAtAllSaysSo) {
  FakeSysfs sys;
  sys.add_platform_tty("ttyS0");
  EXPECT_TRUE(list_usb_ttys(sys.root()).empty());
  auto r = find_usb_tty(0x0403, 0x6010, 1, "", sys.root());
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("no ttyUSB/ttyACM ports at all"), std::string::npos) << r.error().message;
  EXPECT_TRUE(list_usb_ttys("/nonexistent-sysfs").empty());
}

TEST(UartBoardProfiles, TheShippedDmc1BoardLoadsAndTheSpiLoaderLeavesIt) {
  auto uart = load_uart_board_profiles(GPUBRIDGE_TEST_CONFIG_DIR);
  ASSERT_TRUE(uart) << uart.error().message;
  ASSERT_EQ(uart->size(), 1u);
  const auto& p = uart->front();
  EXPECT_EQ(p.name, "icebreaker-dmc1");
  EXPECT_EQ(p.device_kind, protocol::DeviceKind::Dmc1);
  EXPECT_EQ(p.vid, 0x0403);
  EXPECT_EQ(p.pid, 0x6010);
  EXPECT_EQ(p.interface, 1);
  EXPECT_EQ(p.baud, 115200u);
  auto spi = load_board_profiles(GPUBRIDGE_TEST_CONFIG_DIR);
  ASSERT_TRUE(spi) << spi.error().message;
  for (const auto& b : *spi) EXPECT_NE(b.name, "icebreaker-dmc1");
  // Asked for by name where an SPI board is expected, it says what it is and which command takes it.
  auto named = find_board_profile(GPUBRIDGE_TEST_CONFIG_DIR, "icebreaker-dmc1");
  ASSERT_FALSE(named);
  EXPECT_NE(named.error().message.find("is a DMC-1 board on a USB-UART"), std::string::npos) << named.error().message;
  EXPECT_NE(named.error().message.find("render --device dmc1"), std::string::npos);
  auto by_name = find_uart_board_profile(GPUBRIDGE_TEST_CONFIG_DIR, "icebreaker-dmc1");
  ASSERT_TRUE(by_name) << by_name.error().message;
  EXPECT_FALSE(find_uart_board_profile(GPUBRIDGE_TEST_CONFIG_DIR, "icebreaker"));  // an SPI board
}

TEST(UartBoardProfiles, ErrorsNameFileAndKey) {
  const std::string good = R"({"name":"u","device_kind":"dmc1","uart":{"vid":"0x1a86","pid":"0x7523","baud":115200}})";
  auto ok = parse_uart_board_profile(good, "boards/u.json");
  ASSERT_TRUE(ok) << ok.error().message;
  EXPECT_EQ(ok->interface, 0);
  struct Case {
    std::string from, to, key;
  };
  const Case cases[] = {
      {"\"dmc1\"", "\"dmc2\"", "device_kind: unknown \"dmc2\" (spigpu, dmc1)"},
      {"\"dmc1\"", "\"spigpu\"", "device_kind: missing or \"spigpu\""},
      {"115200", "100", "uart.baud: 100 is out of range"},
      {"\"baud\"", "\"interface\":\"E\",\"baud\"", "uart.interface"},
      {"\"baud\"", "\"bauds\"", "uart.bauds: unknown key"},
      {",\"uart\":{\"vid\":\"0x1a86\",\"pid\":\"0x7523\",\"baud\":115200}", "", "uart: missing"},
  };
  for (const auto& c : cases) {
    std::string text = good;
    text.replace(text.find(c.from), c.from.size(), c.to);
    auto r = parse_uart_board_profile(text, "boards/u.json");
    ASSERT_FALSE(r) << c.key;
    EXPECT_NE(r.error().message.find("boards/u.json: " + c.key), std::string::npos) << r.error().message;
  }
  // An SPI profile parser handed a UART board says which command it belongs to.
  auto spi = parse_board_profile(good, "boards/u.json");
  ASSERT_FALSE(spi);
  EXPECT_NE(spi.error().message.find("boards/u.json: device_kind: this is a DMC-1 board"), std::string::npos) << spi.error().message;
}

}  // namespace
}  // namespace gpubridge::usb
