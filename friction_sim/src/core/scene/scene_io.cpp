#include "friction_sim/scene/scene_io.h"

#include "scene/yaml_fields.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>
#include <utility>

namespace friction {

// Names of the scene's enum values in YAML (found by YamlFieldReader through ADL).
const EnumTable<ModelKind> kModelNames{{ModelKind::Lattice2D, "lattice_2d"}, {ModelKind::Chain1D, "chain_1d"}};
const EnumTable<SpringForm> kSpringFormNames{{SpringForm::Geometric, "geometric"},
                                             {SpringForm::Linearised, "linearised"}};
const EnumTable<TopLoadKind> kTopLoadNames{{TopLoadKind::Uniform, "uniform"},
                                           {TopLoadKind::SpringMattress, "spring_mattress"}};
const EnumTable<InterfaceLoading> kInterfaceLoadingNames{{InterfaceLoading::Stuck, "stuck"},
                                                         {InterfaceLoading::Free, "free"}};
const EnumTable<ChainDriving> kDrivingNames{{ChainDriving::Side, "side"}, {ChainDriving::Top, "top"}};
const EnumTable<FrictionLawKind> kLawNames{{FrictionLawKind::AmontonsCoulomb, "amontons_coulomb"},
                                           {FrictionLawKind::SlipWeakening, "slip_weakening"},
                                           {FrictionLawKind::RateState, "rate_state"}};
const EnumTable<IntegratorKind> kSchemeNames{{IntegratorKind::VelocityVerlet, "velocity_verlet"},
                                             {IntegratorKind::RungeKutta4, "rk4"}};
const EnumTable<StageMode> kStageModeNames{
    {StageMode::Velocity, "velocity"}, {StageMode::Hold, "hold"}, {StageMode::Position, "position"}};

const EnumTable<ModelKind>& enumTable(ModelKind) { return kModelNames; }
const EnumTable<SpringForm>& enumTable(SpringForm) { return kSpringFormNames; }
const EnumTable<TopLoadKind>& enumTable(TopLoadKind) { return kTopLoadNames; }
const EnumTable<InterfaceLoading>& enumTable(InterfaceLoading) { return kInterfaceLoadingNames; }
const EnumTable<ChainDriving>& enumTable(ChainDriving) { return kDrivingNames; }
const EnumTable<FrictionLawKind>& enumTable(FrictionLawKind) { return kLawNames; }
const EnumTable<IntegratorKind>& enumTable(IntegratorKind) { return kSchemeNames; }
const EnumTable<StageMode>& enumTable(StageMode) { return kStageModeNames; }

namespace {

/// The shortest text that reads back as `value`, to the last bit: a scene written out (the rig records
/// its scene so, and a rerun reads it) is the scene that ran.
std::string formatNumber(double value) {
  char text[32];
  const auto written = std::to_chars(text, text + sizeof text, value);
  std::string number(text, written.ptr);
  // "3e+09" is a string to YAML 1.1 readers (PyYAML, rosparam): "3.0e+09" is a float to every reader.
  const auto exponent = number.find('e');
  if (exponent != std::string::npos && number.find('.') == std::string::npos) number.insert(exponent, ".0");
  return number;
}

// The one description of the scene's YAML layout, walked by both the reader and the writer so that
// the two cannot drift apart.
// The slider: what it is made of and how it is discretised.
template <class Visitor>
void visitSlider(Scene& s, Visitor& v) {
  v.field("name", s.name);
  v.field("model", s.model);
  v.section("geometry", [&] {
    v.field("length", s.geometry.length);
    v.field("height", s.geometry.height);
    v.field("width", s.geometry.width);
  });
  v.section("material", [&] {
    v.field("density", s.material.density);
    v.field("youngs_modulus", s.material.youngs_modulus);
    v.field("damping_coefficient", s.material.damping_coefficient);
  });
  v.section("lattice", [&] {
    v.field("nodes_x", s.lattice.nodes_x);
    v.field("nodes_z", s.lattice.nodes_z);
    v.field("spring_form", s.lattice.spring_form);
    v.field("foundation_ratio", s.lattice.foundation_ratio);
  });
  v.section("chain", [&] {
    v.field("blocks", s.chain.blocks);
    v.field("driving", s.chain.driving);
    v.field("tilt", s.chain.tilt);
    v.field("torque_share", s.chain.torque_share);
    v.field("initial_shear", s.chain.initial_shear);
  });
}

// How the slider is loaded, driven, integrated, measured and stopped.
template <class Visitor>
void visitRig(Scene& s, Visitor& v) {
  v.section("friction", [&] {
    v.field("law", s.friction.law);
    v.field("static_coefficient", s.friction.static_coefficient);
    v.field("kinetic_coefficient", s.friction.kinetic_coefficient);
    v.field("weakening_length", s.friction.weakening_length);
    v.field("reference_coefficient", s.friction.rate_state.reference_coefficient);
    v.field("direct_effect", s.friction.rate_state.direct_effect);
    v.field("ageing_effect", s.friction.rate_state.ageing_effect);
    v.field("characteristic_slip", s.friction.rate_state.characteristic_slip);
    v.field("reference_speed", s.friction.rate_state.reference_speed);
    v.field("reference_age", s.friction.rate_state.reference_age);
    v.field("initial_age", s.friction.rate_state.initial_age);
    v.field("interfacial_stiffness", s.friction.interfacial_stiffness);
  });
  v.section("load", [&] {
    v.field("normal_force", s.load.normal_force);
    v.field("top", s.load.top);
    v.field("interface_while_loading", s.load.interface_while_loading);
    v.field("mattress_stiffness", s.load.mattress_stiffness);
    v.field("mattress_horizontal_stiffness", s.load.mattress_horizontal_stiffness);
  });
  v.section("pusher", [&] {
    v.field("stiffness", s.pusher.stiffness);
    v.field("height", s.pusher.height);
    v.field("band_min", s.pusher.band_min);
    v.field("band_max", s.pusher.band_max);
  });
  v.section("stage", [&] {
    v.field("max_speed", s.stage.max_speed);
    v.list("program", s.stage.program, [&](StageSegment& segment) {
      v.field("mode", segment.mode);
      v.field("speed", segment.speed);
      v.field("target", segment.target);
      v.field("duration", segment.duration);
    });
  });
  v.section("integrator", [&] {
    v.field("scheme", s.integrator.scheme);
    v.field("time_step", s.integrator.time_step);
    v.field("fast_forward", s.integrator.fast_forward);
  });
  v.section("instruments", [&] {
    v.field("loading_curve_rate", s.instruments.loading_curve_rate);
    v.field("gauge_height", s.instruments.gauge_height);
    v.field("gauge_positions", s.instruments.gauge_positions);
    v.field("front_fit_nodes", s.instruments.front_fit_nodes);
    v.field("event_slip_speed", s.instruments.event_slip_speed);
  });
  v.section("stop", [&] {
    v.field("global_events", s.stop.global_events);
    v.field("time", s.stop.time);
    v.field("stage_travel", s.stop.stage_travel);
  });
}

template <class Visitor>
void visitScene(Scene& s, Visitor& v) {
  visitSlider(s, v);
  visitRig(s, v);
}

class YamlWriter {
 public:
  explicit YamlWriter(YAML::Emitter& out) : out_(out) {}

  template <class T>
  void field(const char* key, T& value) {
    out_ << YAML::Key << key << YAML::Value;
    write(value);
  }
  void section(const char* key, const std::function<void()>& body) {
    out_ << YAML::Key << key << YAML::Value << YAML::BeginMap;
    body();
    out_ << YAML::EndMap;
  }
  template <class T, class Body>
  void list(const char* key, std::vector<T>& items, Body&& body) {
    out_ << YAML::Key << key << YAML::Value << YAML::BeginSeq;
    for (auto& item : items) {
      out_ << YAML::Flow << YAML::BeginMap;
      body(item);
      out_ << YAML::EndMap;
    }
    out_ << YAML::EndSeq;
  }

 private:
  void write(double value) {
    if (std::isinf(value)) {
      out_ << (value > 0 ? ".inf" : "-.inf");
    } else if (std::isnan(value)) {
      out_ << ".nan";  // YAML's, which the reader takes (a field that validation leaves unchecked may hold it)
    } else {
      out_ << formatNumber(value);
    }
  }
  void write(int value) { out_ << value; }
  void write(bool value) { out_ << (value ? "true" : "false"); }
  void write(const std::string& value) { out_ << value; }
  void write(const std::vector<double>& values) {
    out_ << YAML::Flow << YAML::BeginSeq;
    for (double value : values) write(value);
    out_ << YAML::EndSeq;
  }
  template <class E, class = std::enable_if_t<std::is_enum<E>::value>>
  void write(E value) {
    for (const auto& entry : enumTable(E{})) {
      if (entry.first == value) out_ << entry.second;
    }
  }

  YAML::Emitter& out_;
};

}  // namespace

YAML::Node loadMapping(const std::string& text, const std::string& what, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& error) {
    throw ConfigError(what,
                      {"YAML syntax error" + (source.empty() ? "" : " in '" + source + "'") + ": " + error.what()});
  }
  if (!root.IsMap()) throw ConfigError(what, {what + ": expected a mapping at the top level"});
  return root;
}

std::string readTextFile(const std::string& path, std::vector<std::string>& problems) {
  std::ifstream file(path);
  if (!file) {
    problems.push_back("file '" + path + "' cannot be read (" + std::strerror(errno) + ")");
    return {};
  }
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

namespace {
/// The fields of `yaml_text` (from the file `source`, "" for none) read over `base`; problems are
/// collected, the result is not validated.
Scene readFields(const std::string& yaml_text, const std::string& source, const Scene& base,
                 std::vector<std::string>& problems) {
  Scene scene = base;
  YAML::Node root;
  try {
    root = loadMapping(yaml_text, "scene", source);
  } catch (const ConfigError& error) {
    throw SceneError(error.problems());
  }
  YamlFieldReader reader(root, problems);
  visitScene(scene, reader);
  reader.rejectUnknownKeys();
  return scene;
}

/// Validates even after parse problems, so that one refusal lists everything wrong.
Scene validated(const Scene& scene, std::vector<std::string>& problems, double* stability_limit) {
  SceneReview review = validateScene(scene, stability_limit);
  for (auto& problem : review.problems) problems.push_back(std::move(problem));
  if (!problems.empty()) throw SceneError(problems, std::move(review.notes));
  return scene;
}

/// The overrides as one YAML mapping ("pusher.height" → pusher: {height: ...}). Throws SceneError.
std::string overridesYaml(const std::vector<std::pair<std::string, std::string>>& overrides) {
  YAML::Node root(YAML::NodeType::Map);
  std::vector<std::string> problems;
  for (const auto& [key, value] : overrides) {
    std::vector<std::string> parts;
    std::stringstream stream(key);
    for (std::string part; std::getline(stream, part, '.');) parts.push_back(part);
    if (parts.empty() || std::find(parts.begin(), parts.end(), "") != parts.end()) {
      problems.push_back("override '" + key + "': expected a dotted key such as pusher.height");
      continue;
    }
    const std::size_t index = key.find('[');
    if (index != std::string::npos) {
      // A list is one field: it is replaced whole (the unknown key "stage.program[0]" told no more).
      const std::string list = key.substr(0, index);
      problems.push_back("override '" + key +
                         "': an element of a list cannot be set on its own; give the whole list "
                         "in YAML, " +
                         list + "=[...] (as in sweeps/stage_speed.yaml)");
      continue;
    }
    YAML::Node node = root;
    for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
      if (!node[parts[i]]) node[parts[i]] = YAML::Node(YAML::NodeType::Map);
      node.reset(node[parts[i]]);
    }
    try {
      node[parts.back()] = YAML::Load(value);
    } catch (const YAML::Exception& error) {
      problems.push_back("override '" + key + "': value '" + value + "' is not YAML: " + error.what());
    }
  }
  if (!problems.empty()) throw SceneError(problems);
  return YAML::Dump(root);
}
}  // namespace

Scene parseScene(const std::string& yaml_text, const Scene& base, double* stability_limit) {
  std::vector<std::string> problems;
  const Scene scene = readFields(yaml_text, "", base, problems);
  return validated(scene, problems, stability_limit);
}

Scene loadScene(const std::string& path, const std::vector<std::pair<std::string, std::string>>& overrides,
                double* stability_limit) {
  std::vector<std::string> problems;
  const std::string text = readTextFile(path, problems);
  if (!problems.empty()) throw SceneError(problems);
  Scene scene = readFields(text, path, Scene{}, problems);
  // Validated once, with the overrides applied: validation estimates a large lattice's spectrum.
  if (!overrides.empty()) scene = readFields(overridesYaml(overrides), "", scene, problems);
  return validated(scene, problems, stability_limit);
}

Scene overrideScene(const Scene& base, const std::vector<std::pair<std::string, std::string>>& overrides,
                    double* stability_limit) {
  return parseScene(overridesYaml(overrides), base, stability_limit);
}

std::string sceneToYaml(const Scene& scene) {
  Scene copy = scene;
  YAML::Emitter out;
  out << YAML::BeginMap;
  YamlWriter writer(out);
  visitScene(copy, writer);
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

double requireValidScene(const Scene& scene) {
  double limit = 0.0;
  SceneReview review = validateScene(scene, &limit);
  if (!review.problems.empty()) throw SceneError(std::move(review.problems), std::move(review.notes));
  return limit;
}

}  // namespace friction
