#pragma once
// The specification object of a trial record (recorded_trial.hpp) as JSON, for the record's writer, and its
// one reader of a parsed document, for the readers of records that hold it (a study's). Internal.
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "calligraphy/trial/recorded_trial.hpp"

namespace calligraphy::trial_detail {

/// `recorded_trial_json`'s object.
nlohmann::json recorded_trial_object(const RecordedTrial& recorded);

/// A simulated device's physics by field name (the specification's "simulated_device", a record's
/// device.simulated_device).
nlohmann::json simulated_device_object(const SimulatedDeviceParameters& parameters);

/// The one reader of a record's specification (`read_recorded_trial`'s), of a parsed `document`: a record
/// holding it under "specification", or the object alone. Throws DataError naming `source` and the pointer.
RecordedTrial read_recorded_document(const nlohmann::json& document, const std::string& source);

/// A record's text parsed (json_detail::parse_json): a specification's version written beyond a double's
/// range (1e999) is refused as any other version this library does not read, naming those it reads.
nlohmann::json parse_record_text(std::string_view text, const std::string& source);

}  // namespace calligraphy::trial_detail
