#pragma once
/// \file trace_attempts.hpp
/// Marks a simulated writer's attempts in its trial's trace (TrialSample::attempt, ::rewritten), from what
/// the writer meant (its log), so that a reader of the trace (scoring, recognition) can tell the final
/// writing from attempts it wrote again: a stroke written backwards that the display did not take, a
/// refused stroke, a cleared one. The renderer alone cannot tell them, since it does not know which stroke
/// a pen-down segment out of turn was meant as.
#include <vector>

#include "calligraphy/sim/writer_log.hpp"
#include "calligraphy/trial/recorder.hpp"

namespace calligraphy {

/// Sets `attempt` of every sample from an attempt's start (`WriterAttempt::start_s`) up to the next
/// attempt's start (or the trace's end) to that attempt's number at its stroke, 0 before the first, and
/// `rewritten` to whether a later attempt at the same scene stroke followed. Samples must be in time order
/// (they are, as recorded). Replaces the renderer's marks.
void mark_writer_attempts(std::vector<TrialSample>& trace, const WriterLog& log);

}  // namespace calligraphy
