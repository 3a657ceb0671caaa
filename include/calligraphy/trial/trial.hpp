#pragma once
/// \file trial.hpp
/// The trial module in one include: options (options.hpp), one tick at a time (session.hpp), a whole
/// trial on any device (runner.hpp), and what it returns (result.hpp, recorder.hpp).
#include "calligraphy/trial/options.hpp"
#include "calligraphy/trial/recorder.hpp"
#include "calligraphy/trial/result.hpp"
#include "calligraphy/trial/runner.hpp"
#include "calligraphy/trial/session.hpp"
