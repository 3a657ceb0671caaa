#pragma once
// The C interface of the module that calls lib2geom (lib2geom_module.cpp), loaded by lib2geom_nearest.cpp
// when `calligraphy bench nearest` measures lib2geom's column. lib2geom needs glib, cairo, GSL and 27 more
// shared libraries; linked into the program they loaded and were bound at each of its starts. Only numbers
// cross this interface, and no exception leaves the module: failures come back as a status and a message.

#include <cstddef>

extern "C" {

/// The module's file name, and the names of its three functions.
#define CALLIGRAPHY_LIB2GEOM_MODULE_FILE "libcalligraphy_lib2geom.so"

/// A Geom::BezierCurve through `points` (2..5) control points (x[i], y[i]), or null with `error` filled.
using calligraphy_lib2geom_curve_new_fn = void* (*)(const double* x, const double* y, int points, char* error,
                                                    std::size_t error_size);
/// Frees a curve made by calligraphy_lib2geom_curve_new (null is ignored).
using calligraphy_lib2geom_curve_delete_fn = void (*)(void* curve);
/// Geom::nearest_time(p, curve) into out[0], the curve's point there into out[1], out[2], and |B(t) - p|
/// evaluated on the control points relative to p into out[3]. 0, or 1 with `error` filled when lib2geom
/// threw.
using calligraphy_lib2geom_nearest_fn = int (*)(const void* curve, double px, double py, double* out,
                                                char* error, std::size_t error_size);
}
