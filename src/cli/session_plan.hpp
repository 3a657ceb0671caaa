#pragma once
// What `session plan` prints and `session run` prints before it starts: each subject's crossover sequence,
// group, phases with their conditions and item sets, trials and longest duration per session, and how the
// subjects fill the protocol's counterbalancing square. Planned by the study module's schedule
// (plan_session_phases, crossover_assignment, counterbalancing): nothing is assigned here.
#include <span>
#include <string>

#include "calligraphy/study/protocol.hpp"
#include "calligraphy/study/schedule.hpp"

namespace calligraphy::cli {

/// The plan as text, one block of lines per subject, then the balance line and, when the subjects do not
/// fill the square, a line beginning "warning: ". The balance counts `balanced` (the whole study: the
/// subjects already run and these), or `subjects` when it is empty.
[[nodiscard]] std::string session_plan_text(const LoadedProtocol& protocol,
                                            std::span<const SubjectAssignment> subjects,
                                            std::span<const SubjectAssignment> balanced = {});

/// The plan as one JSON document (docs/cli.md, "session plan").
[[nodiscard]] std::string session_plan_json(const LoadedProtocol& protocol,
                                            std::span<const SubjectAssignment> subjects);

}  // namespace calligraphy::cli
