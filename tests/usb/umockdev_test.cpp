// The real libusb code path (LibusbContext enumeration/open, LibusbDevice control/bulk) against
// umockdev: a testbed USB device whose usbfs ioctls are answered by the byte-exact MPSSE model,
// so setup packets and bulk URBs produced by libusb itself are checked by the model. Also
// covers unplug (URBs failing with ENODEV → kDeviceGone). Template: libusb tests/umockdev.c.
#include <gtest/gtest.h>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/usb/emu/mpsse_model.hpp"
#include "gpubridge/usb/emu/reference_target.hpp"
#include "gpubridge/usb/ftdi_mpsse.hpp"
#include "gpubridge/usb/libusb_transport.hpp"
#include "umockdev_bed.hpp"

namespace gpubridge::usb {
namespace {

using testing::Bed;  // the FT232H testbed (umockdev_bed.hpp), shared with the auto-attach test

TEST(Umockdev, RealLibusbPathDrivesTheMpsseModel) {
  Bed bed;
  auto ctx = LibusbContext::create();
  ASSERT_TRUE(ctx) << ctx.error().message;
  auto found = (*ctx)->enumerate({{0x0403, 0x6014}});
  ASSERT_TRUE(found) << found.error().message;
  ASSERT_EQ(found->size(), 1u);
  EXPECT_EQ((*found)[0].info.bcd_device, 0x0900);
  EXPECT_TRUE((*found)[0].accessible) << (*found)[0].problem;
  auto dev = (*ctx)->open(UsbMatch{0x0403, 0x6014, "", ""});
  ASSERT_TRUE(dev) << dev.error().message;
  EXPECT_EQ((*dev)->max_packet_size(0x81), 512) << "wMaxPacketSize from the real descriptor";
  auto bridge = FtdiMpsseBridge::open(**dev, FtdiConfig{});
  ASSERT_TRUE(bridge) << bridge.error().message;
  EXPECT_GT(bed.control_urbs.load(), 8u) << "reset, purges, latency, bitmode went through usbfs";
  const auto frame = protocol::encode(protocol::read_frame(protocol::Reg::ID));
  const SpiWindow w{frame, true, {}};
  auto r = (*bridge)->transfer(std::span(&w, 1));
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r->size(), 9u);
  EXPECT_EQ((*r)[1], 0x53);
  EXPECT_TRUE(bed.model.violations().empty()) << bed.model.violations()[0];

  // Unplug: every later URB fails with ENODEV, which libusb reports as NO_DEVICE.
  bed.model.faults().at_op = bed.model.faults().ops;
  bed.model.faults().fault = emu::UsbFault::NoDevice;
  auto gone = (*bridge)->transfer(std::span(&w, 1));
  ASSERT_FALSE(gone);
  EXPECT_EQ(gone.error().code, backends::kDeviceGone) << gone.error().message;
  EXPECT_NE(gone.error().message.find("unplugged"), std::string::npos);
}

// libusb's asynchronous API (UsbDevice::bulk_stream): IN URBs queued before the commands go out,
// so a read larger than the chip's RX FIFO streams instead of deadlocking the OUT URB.
TEST(Umockdev, StreamedReadsQueueInUrbsWhileTheOutUrbWaits) {
  Bed bed;
  auto ctx = LibusbContext::create();
  ASSERT_TRUE(ctx) << ctx.error().message;
  auto dev = (*ctx)->open(UsbMatch{0x0403, 0x6014, "", ""});
  ASSERT_TRUE(dev) << dev.error().message;
  auto bridge = FtdiMpsseBridge::open(**dev, FtdiConfig{});
  ASSERT_TRUE(bridge) << bridge.error().message;
  std::vector<std::uint8_t> mosi;
  for (int i = 0; i < 300; ++i) protocol::append(mosi, protocol::read_frame(protocol::Reg::ID));  // 2,700 MISO bytes
  const SpiWindow w{mosi, true, {}};
  auto r = (*bridge)->transfer(std::span(&w, 1));
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r->size(), mosi.size());
  for (int i = 0; i < 300; ++i) ASSERT_EQ((*r)[static_cast<std::size_t>(i * 9 + 1)], 0x53) << "frame " << i;
  EXPECT_EQ((*bridge)->stats().streamed_reads, 1u);
  EXPECT_GE(bed.max_in_flight.load(), 2u) << "IN URBs were queued together";
  EXPECT_GT(bed.out_refusals.load(), 0u) << "the OUT URB waited for the RX FIFO to drain: only queued INs let it finish";
  EXPECT_TRUE(bed.model.violations().empty()) << bed.model.violations()[0];

  // Unplug in the middle of a stream: the in-flight URBs fail with ENODEV and are reaped.
  bed.model.faults().at_op = bed.model.faults().ops + 3;
  bed.model.faults().fault = emu::UsbFault::NoDevice;
  auto gone = (*bridge)->transfer(std::span(&w, 1));
  ASSERT_FALSE(gone);
  EXPECT_EQ(gone.error().code, backends::kDeviceGone) << gone.error().message;
  EXPECT_NE(gone.error().message.find("streamed read"), std::string::npos) << gone.error().message;
}

TEST(Umockdev, NothingAttachedIsReportedPlainly) {
  UMockdevTestbed* empty = umockdev_testbed_new();
  auto ctx = LibusbContext::create();
  ASSERT_TRUE(ctx) << ctx.error().message;
  auto dev = (*ctx)->open(UsbMatch{0x0403, 0x6014, "", ""});
  ASSERT_FALSE(dev);
  EXPECT_NE(dev.error().message.find("is attached; plug in the adapter"), std::string::npos) << dev.error().message;
  g_clear_object(&empty);
}

}  // namespace
}  // namespace gpubridge::usb
