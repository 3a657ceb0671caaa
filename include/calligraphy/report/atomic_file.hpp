#pragma once
/// \file atomic_file.hpp
/// `write_file_atomically` and `read_file_for_update` live in the core module
/// (calligraphy/core/atomic_file.hpp), so that every module writes files the same way; this header is
/// kept for code that includes it from here.
#include "calligraphy/core/atomic_file.hpp"
