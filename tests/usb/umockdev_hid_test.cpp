// The real hidapi path (hidapi-libusb: hid_enumerate, hid_open_path, its read thread with an
// interrupt IN transfer in flight, hid_write as an interrupt OUT) against umockdev: a testbed
// MCP2210 whose usbfs ioctls are answered by descriptors, string descriptors and the MCP2210
// report model driving the reference SPI target. A whole board attach (ID, CAPS, strict link),
// an upload and its readback go through it; an unplug must surface as kDeviceGone.
#include <gtest/gtest.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <linux/ioctl.h>
#include <linux/usbdevice_fs.h>
#include <sys/ioctl.h>
#include <umockdev.h>
#include <vector>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/usb/board_factory.hpp"
#include "gpubridge/usb/emu/mcp2210_model.hpp"
#include "gpubridge/usb/emu/reference_target.hpp"
#include "gpubridge/usb/emu/spi_slave.hpp"
#include "gpubridge/usb/hidapi_transport.hpp"
#include "test_profiles.hpp"
#include "umockdev_urbs.hpp"

namespace gpubridge::usb {
namespace {

// String descriptor `index` (0 = the language list) as USB sends it: UTF-16LE after the header.
std::vector<std::uint8_t> string_descriptor(unsigned index) {
  if (index == 0) return {4, 3, 0x09, 0x04};  // English (US)
  const char* s = index == 1 ? "Microchip Technology Inc." : index == 2 ? "MCP2210 USB to SPI Master" : "EMUHID01";
  std::vector<std::uint8_t> d{0, 3};
  for (; *s; ++s) d.insert(d.end(), {static_cast<std::uint8_t>(*s), 0});
  d[0] = static_cast<std::uint8_t>(d.size());
  return d;
}

// One MCP2210 in a umockdev testbed. Interrupt OUT reports go to the model at once; the interrupt
// IN transfer hidapi keeps queued completes only when the model has a response report (a real
// interrupt endpoint NAKs until then). Runs on umockdev's ioctl thread.
struct HidBed {
  emu::ReferenceTarget target{emu::ReferenceTargetConfig{}};
  emu::SpiSlave slave{target, nullptr, [this] { target.tick(); }};
  emu::Mcp2210Model model{&slave, "EMUHID01"};
  UMockdevTestbed* testbed = nullptr;
  UMockdevIoctlBase* handler = nullptr;
  testing::UrbQueue urbs;                // the interrupt IN URB hidapi keeps queued stays in `flying`
  std::atomic<bool> unplugged{false};    // set by the test: every URB fails with ENODEV
  std::atomic<unsigned> reports_out{0}, reports_in{0}, string_requests{0};

  static gboolean on_ioctl(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer self) {
    return static_cast<HidBed*>(self)->handle(client);
  }

  // Standard GET_DESCRIPTOR (strings) is all hidapi asks of endpoint 0 here.
  void control(UMockdevIoctlData* urb_data, std::uint8_t* setup) {
    const std::size_t len = static_cast<std::size_t>(setup[6] | setup[7] << 8);
    if (setup[0] == 0x80 && setup[1] == 6 && setup[3] == 3) {
      ++string_requests;
      const auto d = string_descriptor(setup[2]);
      const std::size_t n = std::min(len, d.size());
      std::memcpy(setup + 8, d.data(), n);
      return urbs.finish(urb_data, 0, n);
    }
    urbs.finish(urb_data, -EPIPE, 0);  // anything else stalls, as an MCP2210 would for unknown requests
  }

  // The interrupt IN URB completes when the model has a response report (or the device is gone).
  void advance() {
    if (urbs.flying.empty()) return;
    if (unplugged) {
      while (!urbs.flying.empty()) urbs.finish_flying(urbs.flying.begin(), -ENODEV, 0);
      return;
    }
    std::uint8_t report[64];
    const int n = model.read(report, 0);
    if (n < 0) return urbs.finish_flying(urbs.flying.begin(), -ENODEV, 0);
    if (n == 0) return;  // NAK: stays in flight
    UMockdevIoctlData* urb_data = urbs.flying.front();
    const usbdevfs_urb& urb = testing::UrbQueue::urb_of(urb_data);
    UMockdevIoctlData* buf = umockdev_ioctl_data_resolve(urb_data, G_STRUCT_OFFSET(usbdevfs_urb, buffer),
                                                          static_cast<gsize>(urb.buffer_length), nullptr);
    const std::size_t len = std::min<std::size_t>(static_cast<std::size_t>(n), static_cast<std::size_t>(buf->data_len));
    std::memcpy(buf->data, report, len);
    umockdev_ioctl_data_unref(buf);
    ++reports_in;
    urbs.finish_flying(urbs.flying.begin(), 0, len);
  }

  gboolean handle(UMockdevIoctlClient* client) {
    const unsigned long request = umockdev_ioctl_client_get_request(client);
    UMockdevIoctlData* arg = umockdev_ioctl_client_get_arg(client);
    switch (request) {
      case USBDEVFS_GET_CAPABILITIES:
        testing::UrbQueue::capabilities(client, arg, USBDEVFS_CAP_BULK_CONTINUATION | USBDEVFS_CAP_NO_PACKET_SIZE_LIM |
                                                         USBDEVFS_CAP_REAP_AFTER_DISCONNECT | USBDEVFS_CAP_ZERO_PACKET);
        return TRUE;
      case USBDEVFS_CLAIMINTERFACE:
      case USBDEVFS_RELEASEINTERFACE:
      case USBDEVFS_CLEAR_HALT:
      case USBDEVFS_RESET:
      case USBDEVFS_RESETEP:
        umockdev_ioctl_client_complete(client, unplugged ? -1 : 0, unplugged ? ENODEV : 0);
        return TRUE;
      case USBDEVFS_SUBMITURB: {
        if (unplugged) {
          umockdev_ioctl_client_complete(client, -1, ENODEV);
          return TRUE;
        }
        UMockdevIoctlData* urb_data = umockdev_ioctl_data_resolve(arg, 0, sizeof(usbdevfs_urb), nullptr);
        const usbdevfs_urb& urb = testing::UrbQueue::urb_of(urb_data);
        UMockdevIoctlData* buf =
            umockdev_ioctl_data_resolve(urb_data, G_STRUCT_OFFSET(usbdevfs_urb, buffer), static_cast<gsize>(urb.buffer_length), nullptr);
        auto* bytes = reinterpret_cast<std::uint8_t*>(buf->data);
        if (urb.type == USBDEVFS_URB_TYPE_CONTROL) {
          control(urb_data, bytes);
        } else if (urb.type == USBDEVFS_URB_TYPE_INTERRUPT && urb.endpoint == 0x01) {
          // hidapi strips report id 0: the model's HidDevice side takes it back.
          std::vector<std::uint8_t> report(1, 0);
          report.insert(report.end(), bytes, bytes + urb.buffer_length);
          ++reports_out;
          const int w = model.write(report);
          urbs.finish(urb_data, w < 0 ? -ENODEV : 0, w < 0 ? 0 : static_cast<std::size_t>(urb.buffer_length));
        } else if (urb.type == USBDEVFS_URB_TYPE_INTERRUPT && urb.endpoint == 0x81) {
          urbs.flying.push_back(urb_data);
        } else {
          urbs.finish(urb_data, -EPIPE, 0);
        }
        umockdev_ioctl_data_unref(buf);
        umockdev_ioctl_client_complete(client, 0, 0);
        return TRUE;
      }
      default:
        return urbs.handle_common(request, client, arg, [this] { advance(); }) ? TRUE : FALSE;
    }
  }

  // MCP2210: 04d8:00de, strings 1-3, one HID interface (class 3) with a 29-byte vendor report
  // descriptor and interrupt endpoints 0x81 IN / 0x01 OUT of 64 bytes.
  HidBed() {
    testbed = umockdev_testbed_new();
    handler = umockdev_ioctl_base_new();
    g_signal_connect(handler, "handle-ioctl", reinterpret_cast<GCallback>(reinterpret_cast<void (*)()>(&HidBed::on_ioctl)), this);
    umockdev_testbed_attach_ioctl(testbed, "/dev/bus/usb/001/002", handler, nullptr);
    umockdev_testbed_add_from_string(testbed,
                                     "P: /devices/usb1/1-1\n"
                                     "N: bus/usb/001/002\n"
                                     "E: SUBSYSTEM=usb\n"
                                     "E: DEVNAME=/dev/bus/usb/001/002\n"
                                     "E: DEVTYPE=usb_device\n"
                                     "E: BUSNUM=001\n"
                                     "E: DEVNUM=002\n"
                                     "A: busnum=1\\n\n"
                                     "A: devnum=2\\n\n"
                                     "A: devpath=1\\n\n"
                                     "A: bConfigurationValue=1\\n\n"
                                     "A: speed=12\\n\n"
                                     "H: descriptors=1201000200000040d804de00000101020301"  // device
                                     "090229000101008032090400000203000000"                 // config, interface
                                     "092111010001221d000705810340000107050103400001\n",   // HID, EP 0x81, EP 0x01
                                     nullptr);
  }
  ~HidBed() {
    urbs.clear();
    g_clear_object(&handler);
    g_clear_object(&testbed);
  }
};

TEST(UmockdevHid, RealHidapiPathAttachesAnMcp2210BoardAndSeesTheUnplug) {
  HidBed bed;
  auto ctx = HidapiContext::create();
  ASSERT_TRUE(ctx) << ctx.error().message;
  const auto found = (*ctx)->enumerate(0x04d8, 0x00de);
  ASSERT_EQ(found.size(), 1u) << "hid_enumerate through libusb found no MCP2210 in the testbed";
  EXPECT_EQ(found[0].serial, "EMUHID01") << "serial read as a string descriptor";
  EXPECT_EQ(found[0].product, "MCP2210 USB to SPI Master");
  EXPECT_GT(bed.string_requests.load(), 0u);

  BoardProfile profile = test::profile_for(BridgeChip::MCP2210);
  profile.serial = "EMUHID01";
  auto board = open_board(profile, BoardOpenOptions{});  // not emulated: hidapi → libusb → usbfs
  ASSERT_TRUE(board) << board.error().message;
  EXPECT_GT(bed.reports_out.load(), 3u) << "chip settings, SPI settings and transfers went out as interrupt reports";
  EXPECT_GT(bed.reports_in.load(), 3u) << "their responses came back through hidapi's read thread";

  std::vector<std::uint8_t> data(200);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<std::uint8_t>(i * 7 + 3);
  ASSERT_TRUE((*board)->upload(0x400, data));
  auto back = (*board)->readback(0x400, static_cast<std::uint32_t>(data.size()));
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(*back, data);
  EXPECT_TRUE(bed.model.violations().empty()) << bed.model.violations()[0];

  bed.unplugged = true;
  auto gone = (*board)->readback(0x400, 16);
  ASSERT_FALSE(gone);
  EXPECT_EQ(gone.error().code, backends::kDeviceGone) << gone.error().message;
}

}  // namespace
}  // namespace gpubridge::usb
