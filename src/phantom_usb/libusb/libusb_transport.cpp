#include "phantom_usb/libusb/libusb_transport.hpp"

#include <libusb.h>

#include <algorithm>
#include <cstdio>
#include <utility>

#include "calligraphy/core/errors.hpp"
#include "devices/phantom/usb_ids.hpp"

namespace calligraphy::phantom {
namespace {

unsigned int libusb_timeout_ms(std::chrono::microseconds timeout) noexcept {
  return static_cast<unsigned int>(std::max<std::int64_t>(1, (timeout.count() + 999) / 1000));
}

std::string error_text(int code) { return libusb_error_name(code); }

struct Endpoints {
  int interface_number = -1;
  std::uint8_t in = 0;
  std::uint8_t out = 0;
};

// The first interface (alternate setting 0) with both a bulk IN and a bulk OUT endpoint.
Endpoints find_bulk_endpoints(libusb_device* device) {
  libusb_config_descriptor* config = nullptr;
  if (libusb_get_active_config_descriptor(device, &config) != 0) return {};
  Endpoints found;
  for (int i = 0; i < config->bNumInterfaces && found.interface_number < 0; ++i) {
    const libusb_interface& interface = config->interface[i];
    if (interface.num_altsetting < 1) continue;
    const libusb_interface_descriptor& setting = interface.altsetting[0];
    Endpoints candidate;
    for (int e = 0; e < setting.bNumEndpoints; ++e) {
      const libusb_endpoint_descriptor& endpoint = setting.endpoint[e];
      if ((endpoint.bmAttributes & LIBUSB_TRANSFER_TYPE_MASK) != LIBUSB_TRANSFER_TYPE_BULK) continue;
      if ((endpoint.bEndpointAddress & LIBUSB_ENDPOINT_DIR_MASK) == LIBUSB_ENDPOINT_IN) {
        candidate.in = endpoint.bEndpointAddress;
      } else {
        candidate.out = endpoint.bEndpointAddress;
      }
    }
    if (candidate.in != 0 && candidate.out != 0) {
      candidate.interface_number = setting.bInterfaceNumber;
      found = candidate;
    }
  }
  libusb_free_config_descriptor(config);
  return found;
}

}  // namespace

std::vector<UsbDeviceEntry> find_usb_phantoms() {
  libusb_context* context = nullptr;
  if (const int rc = libusb_init(&context); rc != 0)
    throw CommunicationError("libusb: init failed: " + error_text(rc));
  std::vector<UsbDeviceEntry> found;
  libusb_device** list = nullptr;
  const ssize_t count = libusb_get_device_list(context, &list);
  for (ssize_t i = 0; i < count; ++i) {
    libusb_device_descriptor descriptor{};
    if (libusb_get_device_descriptor(list[i], &descriptor) != 0) continue;
    if (!is_reported_touch_id(descriptor.idVendor, descriptor.idProduct)) continue;
    found.push_back({libusb_get_bus_number(list[i]), libusb_get_device_address(list[i]), descriptor.idVendor,
                     descriptor.idProduct});
  }
  if (count >= 0) libusb_free_device_list(list, 1);
  libusb_exit(context);
  return found;
}

LibusbTransport::LibusbTransport(UsbDeviceEntry entry) : entry_(entry) {}

LibusbTransport::~LibusbTransport() { close(); }

void LibusbTransport::open() {
  if (handle_ != nullptr) return;
  if (const int rc = libusb_init(&context_); rc != 0)
    throw CommunicationError("libusb: init failed: " + error_text(rc));
  libusb_device** list = nullptr;
  const ssize_t count = libusb_get_device_list(context_, &list);
  libusb_device* target = nullptr;
  for (ssize_t i = 0; i < count; ++i) {
    if (libusb_get_bus_number(list[i]) == entry_.bus &&
        libusb_get_device_address(list[i]) == entry_.address) {
      target = libusb_ref_device(list[i]);
    }
  }
  if (count >= 0) libusb_free_device_list(list, 1);
  if (target == nullptr) {
    close();
    throw DeviceNotFound(description() + ": no longer attached");
  }
  const Endpoints endpoints = find_bulk_endpoints(target);
  const int open_rc = libusb_open(target, &handle_);
  libusb_unref_device(target);
  if (open_rc == LIBUSB_ERROR_ACCESS) {
    {
      close();
      throw DeviceNotFound(description() + ": permission denied (a udev rule granting access is needed)");
    }
  }
  if (open_rc != 0) {
    close();
    throw CommunicationError(description() + ": open failed: " + error_text(open_rc));
  }
  if (endpoints.interface_number < 0) {
    close();
    throw DeviceNotFound(description() + ": no interface with bulk IN and OUT");
  }
  libusb_set_auto_detach_kernel_driver(handle_, 1);  // e.g. cdc_acm holds the Touch's serial interface
  if (const int rc = libusb_claim_interface(handle_, endpoints.interface_number); rc != 0) {
    {
      close();
      throw CommunicationError(description() + ": cannot claim interface: " + error_text(rc));
    }
  }
  interface_number_ = endpoints.interface_number;
  endpoint_in_ = endpoints.in;
  endpoint_out_ = endpoints.out;
}

void LibusbTransport::close() noexcept {
  if (handle_ != nullptr) {
    if (interface_number_ >= 0) libusb_release_interface(handle_, interface_number_);
    libusb_close(handle_);
  }
  handle_ = nullptr;
  interface_number_ = -1;
  if (context_ != nullptr) libusb_exit(context_);
  context_ = nullptr;
}

DeviceFault LibusbTransport::write(std::span<const std::uint8_t> packet,
                                   std::chrono::microseconds timeout) noexcept {
  // Codes, not exceptions: the servo path neither throws nor builds a string, also when it fails.
  if (handle_ == nullptr) return DeviceFault::not_open;
  if (packet.size() > out_buffer_.size()) return DeviceFault::link_lost;  // longer than 64 bytes: refused
  std::copy(packet.begin(), packet.end(), out_buffer_.begin());
  int sent = 0;
  const int rc = libusb_bulk_transfer(handle_, endpoint_out_, out_buffer_.data(),
                                      static_cast<int>(packet.size()), &sent, libusb_timeout_ms(timeout));
  // Unplugged (LIBUSB_ERROR_NO_DEVICE), any other failure, or a short write.
  if (rc != 0 || sent != static_cast<int>(packet.size())) return DeviceFault::link_lost;
  return DeviceFault::none;
}

DeviceFault LibusbTransport::read(std::span<std::uint8_t> buffer, std::chrono::microseconds timeout,
                                  std::size_t& received) noexcept {
  received = 0;
  if (handle_ == nullptr) return DeviceFault::not_open;
  int count = 0;
  const int rc = libusb_bulk_transfer(handle_, endpoint_in_, buffer.data(), static_cast<int>(buffer.size()),
                                      &count, libusb_timeout_ms(timeout));
  if (rc == 0 || rc == LIBUSB_ERROR_TIMEOUT) {
    received = static_cast<std::size_t>(count);
    return DeviceFault::none;
  }
  if (rc == LIBUSB_ERROR_OVERFLOW) {  // longer than the buffer: the caller rejects it
    received = buffer.size();
    return DeviceFault::none;
  }
  return DeviceFault::link_lost;  // unplugged (LIBUSB_ERROR_NO_DEVICE) or another libusb error
}

std::string LibusbTransport::description() const {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "libusb bus %u address %u (%04x:%04x)", entry_.bus, entry_.address,
                entry_.vendor_id, entry_.product_id);
  return buffer;
}

}  // namespace calligraphy::phantom
