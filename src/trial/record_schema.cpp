#include "trial/record_schema.hpp"

#include <vector>

#include "calligraphy/trial/recorded_trial.hpp"

namespace calligraphy {

const Schema& SchemaOf<FixedGuidance>::get() { return table_schema<FixedGuidance>("the paper's fixture"); }
const Schema& SchemaOf<FadingGuidance>::get() { return table_schema<FadingGuidance>("fading guidance"); }
const Schema& SchemaOf<ReplayGuidance>::get() {
  return table_schema<ReplayGuidance>("a teacher's recording replayed (the teacher is named by the trial)");
}
const Schema& SchemaOf<AssistAsNeededGuidance>::get() {
  return table_schema<AssistAsNeededGuidance>("assist-as-needed guidance");
}
const Schema& SchemaOf<ErrorAmplificationGuidance>::get() {
  return table_schema<ErrorAmplificationGuidance>("error amplification");
}
const Schema& SchemaOf<TimingGuidance>::get() { return table_schema<TimingGuidance>("timing guidance"); }
int trial_detail::acceptance_field_version(std::string_view name) {
  if (name == "miss_min_path_m") return 8;
  if (name.starts_with("centred_")) return 7;
  if (name == "end_gap_m" || name == "end_gap_fraction") return 5;
  return 4;
}

const Schema& SchemaOf<StrokeAcceptance>::get() {
  // The fields after the eighth came with version 4 of a trial record: an older record lacks them and
  // runs with the fixed tolerances it ran with (StrokeAcceptance::use_fixed_tolerances, recorded_trial.cpp).
  // The end gap's floor (the last two) came with version 5: a version-4 record runs without it
  // (StrokeAcceptance::use_version_4_end_gaps). The centred rule (the last four) came with version 7: an
  // older record runs without it (StrokeAcceptance::use_version_6_coverage). The miss's least path came with
  // version 8 (StrokeAcceptance::use_version_7_misses).
  static const std::vector<SchemaField> fields = [] {
    std::vector<SchemaField> out = table_fields<StrokeAcceptance>();
    for (std::size_t i = 8; i < out.size(); ++i)
      out[i] = since(trial_detail::acceptance_field_version(out[i].name), out[i]);
    return out;
  }();
  static const Schema schema{.name = ParameterTable<StrokeAcceptance>::name,
                             .doc = "when a stroke counts as written",
                             .fields = fields,
                             .defaults = default_of<StrokeAcceptance>,
                             .check_rules = validate_of<StrokeAcceptance>};
  return schema;
}
const Schema& SchemaOf<SafetyChainParameters>::get() {
  return table_schema<SafetyChainParameters>("the renderer's safety chain",
                                             validate_of<SafetyChainParameters>);
}

const Schema& SchemaOf<NearestPointOptions>::get() {
  static const std::vector<SchemaField> fields{
      enum_field<&NearestPointOptions::method>("method", {.doc = "the nearest-point search"}),
      number_field<&NearestPointOptions::tolerance>(
          "tolerance", kForceLawNearestToleranceRange,
          {.doc = "tolerance of the parameter search (exact: in t; subdivision: the paper's e, in m)"}),
      integer_field<&NearestPointOptions::newton_starts>("newton_starts", 1, 1000,
                                                         {.doc = "newton: number of starts"}),
      integer_field<&NearestPointOptions::newton_iterations>("newton_iterations", 1, 1000,
                                                             {.doc = "newton: iterations per start"}),
  };
  static const Schema schema{.name = "NearestPointOptions",
                             .doc = "the nearest point on an element (section 4.3)",
                             .fields = fields,
                             .defaults = default_of<NearestPointOptions>};
  return schema;
}

const Schema& SchemaOf<ForceLawParameters>::get() {
  static const std::vector<SchemaField> fields = [] {
    std::vector<SchemaField> out = table_fields<ForceLawParameters>();
    out.push_back(boolean_field<&ForceLawParameters::guidance>(
        "guidance", {.doc = "in-plane guidance on (the paper force is always rendered)"}));
    out.push_back(variant_field<&ForceLawParameters::guidance_law, GuidanceMode>(
        "guidance_law", "mode", {.doc = "how F_et attracts, with the mode's own parameters"}));
    out.push_back(object_field<&ForceLawParameters::acceptance>("acceptance",
                                                                {.doc = "when a stroke counts as written"}));
    out.push_back(object_field<&ForceLawParameters::nearest>("nearest", {.doc = "the nearest-point search"}));
    return out;
  }();
  // Its rules (ForceLawParameters::validate) need a replay's teacher, which a record does not hold: the
  // record's reader checks them with a stand-in.
  static const Schema schema{.name = "ForceLawParameters",
                             .doc = "the force law F_e = F_en + F_et (Wang, Zhang & Yao 2006, eqs. 7-9)",
                             .fields = fields,
                             .defaults = default_of<ForceLawParameters>};
  return schema;
}

const Schema& SchemaOf<PassivityParameters>::get() {
  static const std::vector<SchemaField> fields = [] {
    std::vector<SchemaField> out{
        boolean_field<&PassivityParameters::enabled>("enabled", {.doc = "observer and controller on"})};
    for (const SchemaField& field : table_fields<PassivityParameters>()) out.push_back(field);
    return out;
  }();
  static const Schema schema{.name = "PassivityParameters",
                             .doc = "the passivity observer and controller (Hannaford & Ryu 2002)",
                             .fields = fields,
                             .defaults = default_of<PassivityParameters>,
                             .check_rules = validate_of<PassivityParameters>};
  return schema;
}

const Schema& SchemaOf<WriterProfile>::get() {
  static const std::vector<SchemaField> fields = [] {
    std::vector<SchemaField> out{string_field<&WriterProfile::name>("name", {.doc = "the profile's name"})};
    for (const SchemaField& field : table_fields<WriterProfile>()) out.push_back(field);
    // The one whole number of the profile, outside its table of numbers (writer_profile.hpp).
    out.push_back(integer_field<&WriterProfile::max_attempts_per_stroke>(
        "max_attempts_per_stroke", 1, 1000, {.doc = "attempts at one stroke before the writer gives up"}));
    return out;
  }();
  static const Schema schema{.name = "WriterProfile",
                             .doc = "the simulated writer's profile as it wrote",
                             .fields = fields,
                             .defaults = default_of<WriterProfile>,
                             .check_rules = validate_of<WriterProfile>};
  return schema;
}

const Schema& SchemaOf<DeviceInfo>::get() {
  using I = DeviceInfo;
  // Any finite figure a caller gives (Python's DeviceInfo) is read: none is refused for its size.
  static const std::vector<SchemaField> fields{
      string_field<&I::model>("model", {.doc = "the model the device reports"}),
      string_field<&I::manufacturer>("manufacturer", {.doc = "its manufacturer"}),
      number_field<&I::max_force_n>(
          "max_force_n", kPositiveRange,
          {.unit = "N",
           .doc = "peak force; the safety chain's peak (0 there: the device's) is at most this"}),
      number_field<&I::max_continuous_force_n>(
          "max_continuous_force_n", kNonNegativeRange,
          {.unit = "N", .doc = "force sustainable for minutes; 0: unknown (the continuous stage off)"}),
      number_field<&I::max_stiffness_n_per_m>("max_stiffness_n_per_m", kNonNegativeRange,
                                              {.unit = "N/m", .doc = "highest stable stiffness at 1 kHz"}),
      number_field<&I::max_damping_n_s_per_m>("max_damping_n_s_per_m", kNonNegativeRange,
                                              {.unit = "N s/m", .doc = "highest stable damping"}),
      number_field<&I::intrinsic_damping_n_s_per_m>(
          "intrinsic_damping_n_s_per_m", kNonNegativeRange,
          {.unit = "N s/m",
           .doc = "the device's own damping as given (the simulation reports its damping b)"}),
      number_field<&I::workspace_radius_m>("workspace_radius_m", kNonNegativeRange,
                                           {.unit = "m", .doc = "radius of a sphere inside the workspace"}),
      number_array_field<&I::workspace_size_m, 3>("workspace_size_m", kNonNegativeRange,
                                                  {.unit = "m", .doc = "box of the usable workspace, x y z"}),
  };
  // Its defaults are DeviceInfo's own, as every struct's (a record before version 9 lacks the object whole
  // and takes SimulatedDeviceParameters' figures, the simulated Phantom Desktop's).
  static const Schema schema{.name = "DeviceInfo",
                             .doc = "what the simulated device reports it can do",
                             .fields = fields,
                             .defaults = default_of<DeviceInfo>};
  return schema;
}

const Schema& SchemaOf<SimulatedDeviceParameters>::get() {
  using P = SimulatedDeviceParameters;
  static const std::vector<SchemaField> fields{
      number_field<&P::moving_mass_kg>("moving_mass_kg", {.low = 1e-4, .high = 1e3},
                                       {.unit = "kg", .doc = "stylus, linkage and hand together"}),
      number_field<&P::damping_n_s_per_m>("damping_n_s_per_m", {.low = 0.0, .high = 1e4},
                                          {.unit = "N s/m", .doc = "device viscous damping b"}),
      number_field<&P::encoder_resolution_m>("encoder_resolution_m", {.low = 0.0, .high = 1e-3},
                                             {.unit = "m", .doc = "position quantum: 0 or at least 1e-9 m"}),
      number_field<&P::velocity_cutoff_hz>("velocity_cutoff_hz", {.low = 0.0, .high = 1e6, .low_open = true},
                                           {.unit = "Hz", .doc = "low-pass on the differenced velocity"}),
      integer_field<&P::physics_substeps>("physics_substeps", 1, 10000,
                                          {.doc = "least number of integration steps per servo tick"}),
      number_field<&P::physics_rate_hz>("physics_rate_hz", {.low = 1e3, .high = 1e8},
                                        {.unit = "Hz", .doc = "least physics rate"}),
      number_array_field<&P::initial_position_m, 3>("initial_position_m", kLayoutOffsetRange,
                                                    {.unit = "m", .doc = "where the stylus starts"}),
      // Version 9: the figures bound the trial's forces (the safety chain's 0 is the device's peak), so a
      // re-run must report the same; an older record's device reports the simulated Phantom Desktop's.
      since(trial_detail::kDeviceInfoRecordVersion,
            object_field<&P::info>("info", {.doc = "the figures the device reports (its force limits)"})),
  };
  static const Schema schema{.name = "SimulatedDeviceParameters",
                             .doc = "the physics of a simulated device its caller made",
                             .fields = fields,
                             .defaults = default_of<P>,
                             .check_rules = validate_of<P>};
  return schema;
}

const Schema& SchemaOf<SceneLayout>::get() {
  using L = SceneLayout;
  static const std::vector<SchemaField> fields{
      number_field<&L::character_size_m>("character_size_m", kLayoutSizeRange,
                                         {.unit = "m", .doc = "side of each character's data box on paper"}),
      number_field<&L::spacing_m>("spacing_m", kLayoutSizeRange,
                                  {.unit = "m", .doc = "centre-to-centre distance in the row"}),
      number_array_field<&L::centre_m, 2>("centre_m", kLayoutOffsetRange,
                                          {.unit = "m", .doc = "centre of the row on the paper"}),
      number_field<&L::paper_z_m>("paper_z_m", kLayoutOffsetRange,
                                  {.unit = "m", .doc = "z0, height of the paper plane in device space"}),
      number_field<&L::box_margin_m>("box_margin_m", kLayoutMarginRange,
                                     {.unit = "m", .doc = "bounding box margin around the strokes (Fig. 5)"}),
      number_field<&L::start_radius_m>(
          "start_radius_m", kLayoutRadiusRange,
          {.unit = "m", .doc = "radius of the start-point neighbourhood (Fig. 5, Table 1)"}),
  };
  static const Schema schema{.name = "SceneLayout",
                             .doc = "where the characters are placed on the paper",
                             .fields = fields,
                             .defaults = default_of<L>};
  return schema;
}

const Schema& SchemaOf<trial_detail::RecordedScene>::get() {
  using S = trial_detail::RecordedScene;
  static const std::vector<SchemaField> fields{
      object_field<&S::layout>("layout", {.doc = "where the characters were placed"}),
      string_field<&S::sha256>(
          "sha256", {.doc = "SHA-256 of the placed characters (hex)", .format = StringFormat::sha256}),
  };
  static const Schema schema{.name = "RecordedScene",
                             .doc = "the scene the trial ran on",
                             .fields = fields,
                             .defaults = default_of<S>};
  return schema;
}

const Schema& SchemaOf<trial_detail::RecordDocument>::get() {
  using R = trial_detail::RecordDocument;
  static const std::vector<SchemaField> fields{
      string_field<&R::format>("format", {.doc = "the format's name", .format = StringFormat::constant}),
      integer_field<&R::version>("version", kOldestRecordedTrialVersion, kRecordedTrialVersion,
                                 {.doc = "the format's version"}),
      object_field<&R::trial>("trial", {.doc = "the trial as stated, its outputs cleared"}),
      object_field<&R::force_law>("force_law", {.doc = "the force law the renderer ran"}),
      object_field<&R::safety>("safety", {.doc = "the safety chain (0 forces: the device's)"}),
      object_field<&R::passivity>("passivity", {.doc = "the passivity controller"}),
      optional_object_field<&R::writer>("writer",
                                        {.doc = "the simulated writer as it wrote; null: a person"}),
      optional_object_field<&R::simulated_device>(
          "simulated_device", {.doc = "a simulated device's physics; null: the registry's device"}),
      object_field<&R::scene>("scene", {.doc = "the scene's layout and the characters' SHA-256"}),
      string_field<&R::library_version>("library_version", {.doc = "the library that ran it"}),
      since(4, string_field<&R::teacher_sha256>(
                   "teacher_sha256",
                   {.doc = "lower-case hex SHA-256 of the teacher's recording a replay ran on, "
                           "checked when it is re-run; required when the replay names its file "
                           "(/trial/teacher); empty: no file was read (a teacher given as samples)",
                    .source = "FIPS 180-4",
                    .format = StringFormat::sha256})),
  };
  static const Schema schema{.name = "RecordedTrial",
                             .doc = "a trial as it ran, whole: what `calligraphy trial --spec` runs again",
                             .fields = fields,
                             .defaults = default_of<R>};
  return schema;
}

}  // namespace calligraphy
