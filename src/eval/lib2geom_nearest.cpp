#include "eval/lib2geom_nearest.hpp"

#include <dlfcn.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <string>
#include <system_error>

#include "calligraphy/core/errors.hpp"
#include "eval/lib2geom_module/lib2geom_module.hpp"

namespace calligraphy::cli {

namespace {

void require_finite(const Vec2& v, const std::string& what) {
  if (!std::isfinite(v.x()) || !std::isfinite(v.y())) {
    throw InvalidArgument("lib2geom nearest point: " + what + " is not finite");
  }
}

void require_element(const StrokeElement& element) {
  if (element.degree < 1 || element.degree > kMaxElementDegree) {
    throw InvalidArgument("lib2geom nearest point: element degree " + std::to_string(element.degree) +
                          " is not 1.." + std::to_string(kMaxElementDegree));
  }
  for (int i = 0; i <= element.degree; ++i) {
    require_finite(element.control[static_cast<std::size_t>(i)], "control point " + std::to_string(i));
  }
}

// The module that calls lib2geom, loaded once, on first use, from beside the program: build and install
// put it at CALLIGRAPHY_LIB2GEOM_MODULE_DIR relative to the directory of the running executable.
struct Lib2geomModule {
  calligraphy_lib2geom_curve_new_fn curve_new = nullptr;
  calligraphy_lib2geom_curve_delete_fn curve_delete = nullptr;
  calligraphy_lib2geom_nearest_fn nearest = nullptr;
  std::string missing;  ///< why it is not loaded; empty when loaded
};

Lib2geomModule load_module() {
  Lib2geomModule module;
#ifdef CALLIGRAPHY_LIB2GEOM_MODULE_DIR
  std::error_code error;
  const std::filesystem::path program = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) {
    module.missing = "the running program's path is unknown (/proc/self/exe: " + error.message() + ")";
    return module;
  }
  const std::filesystem::path file =
      program.parent_path() / CALLIGRAPHY_LIB2GEOM_MODULE_DIR / CALLIGRAPHY_LIB2GEOM_MODULE_FILE;
  void* handle = ::dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* why = ::dlerror();
    module.missing = "its module does not load (" + std::string(why != nullptr ? why : file.string()) + ")";
    return module;
  }
  module.curve_new =
      reinterpret_cast<calligraphy_lib2geom_curve_new_fn>(::dlsym(handle, "calligraphy_lib2geom_curve_new"));
  module.curve_delete = reinterpret_cast<calligraphy_lib2geom_curve_delete_fn>(
      ::dlsym(handle, "calligraphy_lib2geom_curve_delete"));
  module.nearest =
      reinterpret_cast<calligraphy_lib2geom_nearest_fn>(::dlsym(handle, "calligraphy_lib2geom_nearest"));
  if (module.curve_new == nullptr || module.curve_delete == nullptr || module.nearest == nullptr) {
    module.missing = "its module " + file.string() + " lacks a function";
  }
#else
  module.missing = "this build has no lib2geom (install lib2geom-dev and configure again)";
#endif
  return module;
}

const Lib2geomModule& lib2geom_module() {
  static const Lib2geomModule module = load_module();
  return module;
}

}  // namespace

bool lib2geom_built() { return lib2geom_module().missing.empty(); }

std::string lib2geom_missing() { return lib2geom_module().missing; }

struct Lib2geomCurve::Curve {
  void* curve = nullptr;
  ~Curve() { lib2geom_module().curve_delete(curve); }
};

Lib2geomCurve::Lib2geomCurve(const StrokeElement& element) {
  require_element(element);
  if (!lib2geom_built()) throw Error("lib2geom nearest point: " + lib2geom_missing());
  // Bernstein coefficients per axis are the control points' coordinates.
  std::array<double, kMaxElementDegree + 1> x{};
  std::array<double, kMaxElementDegree + 1> y{};
  for (int i = 0; i <= element.degree; ++i) {
    x[static_cast<std::size_t>(i)] = element.control[static_cast<std::size_t>(i)].x();
    y[static_cast<std::size_t>(i)] = element.control[static_cast<std::size_t>(i)].y();
  }
  std::array<char, 256> message{};
  void* curve =
      lib2geom_module().curve_new(x.data(), y.data(), element.degree + 1, message.data(), message.size());
  if (curve == nullptr) throw Error(std::string("lib2geom nearest point: ") + message.data());
  curve_ = std::make_unique<Curve>();
  curve_->curve = curve;
}

NearestPoint Lib2geomCurve::nearest(const Vec2& p) const {
  require_finite(p, "the query point");
  std::array<double, 4> out{};
  std::array<char, 256> message{};
  if (lib2geom_module().nearest(curve_->curve, p.x(), p.y(), out.data(), message.data(), message.size()) !=
      0) {
    throw Error(std::string("lib2geom nearest point: Geom::nearest_time threw: ") + message.data());
  }
  NearestPoint result;
  result.t = out[0];
  result.foot = Vec2(out[1], out[2]);
  result.distance = out[3];
  return result;
}

Lib2geomCurve::~Lib2geomCurve() = default;
Lib2geomCurve::Lib2geomCurve(Lib2geomCurve&&) noexcept = default;
Lib2geomCurve& Lib2geomCurve::operator=(Lib2geomCurve&&) noexcept = default;

}  // namespace calligraphy::cli
