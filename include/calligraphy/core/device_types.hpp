#pragma once
/// \file device_types.hpp
/// The value types a haptic device and the renderer exchange, in SI units: positions in m, velocities
/// in m/s, forces in N, stiffness in N/m, damping in N s/m, time in s. Device coordinates: x right,
/// y away from the writer, z up out of the paper. They live in `core` because the renderer (below the
/// device layer) reads a `DeviceState` and sizes its forces from a `DeviceInfo`.
#include <cstdint>
#include <string>

#include "calligraphy/core/geometry.hpp"

namespace calligraphy {

/// The farthest a haptic device's tip reaches from its origin along any axis [m]: the Phantom models'
/// workspaces are at most 0.12 m in radius (Premium 1.5; CHAI3D's per-model values, phantom_models.hpp),
/// so 1 m bounds every desktop device with a margin. A scene's layout lies within it (kMaxLayoutOffsetM,
/// scene.hpp), a simulated pen starts within it, and the renderer takes a reading beyond kMaxDeviceReadingM
/// for a fault.
inline constexpr double kDeviceReachM = 1.0;
/// The largest coordinate of a device reading the renderer uses [m]: ten times the reach, so a scene at the
/// edge of the reach (a character up to 1 m wide, its row 1 m away) is still rendered; a reading beyond it
/// (a garbled driver value, 1e304 m) gives zero force, as a non-finite one does (`input_rejected`).
inline constexpr double kMaxDeviceReadingM = 10.0 * kDeviceReachM;

/// What a device can do, in SI units (after CHAI3D's cHapticDeviceInfo).
struct DeviceInfo {
  std::string model;                    ///< e.g. "Phantom Desktop (simulated)"
  std::string manufacturer;             ///< e.g. "calligraphy"
  double max_force_n = 0.0;             ///< peak force [N]
  double max_continuous_force_n = 0.0;  ///< force sustainable for minutes [N]
  double max_stiffness_n_per_m = 0.0;   ///< highest stable stiffness at 1 kHz [N/m]
  double max_damping_n_s_per_m = 0.0;   ///< highest stable damping [N s/m]
  /// The device's own physical damping [N s/m], which raises the stiffness a sampled loop can render
  /// passively (Colgate & Schenkel 1997: b > K T / 2 + |B|); 0 when unknown.
  double intrinsic_damping_n_s_per_m = 0.0;
  double workspace_radius_m = 0.0;       ///< radius of a sphere inside the workspace [m]
  Vec3 workspace_size_m = Vec3::Zero();  ///< box of the usable workspace, x y z [m]
};

/// A snapshot of the device, as read once per servo tick.
struct DeviceState {
  Vec3 position_m = Vec3::Zero();    ///< tip (HIP) position [m]
  Vec3 velocity_m_s = Vec3::Zero();  ///< tip velocity [m/s]
  std::uint32_t buttons = 0;         ///< bit i set when button i is pressed
  /// Time stamp [s] on the device's own clock: monotonic, seconds, origin the device's (the simulated
  /// device counts from its open(), OpenHaptics from the machine's boot). Only differences are meaningful:
  /// a trial counts its times from its first tick (`TrialSession`).
  double time_s = 0.0;
};

}  // namespace calligraphy
