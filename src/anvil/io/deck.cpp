#include "anvil/io/deck.hpp"

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <span>
#include <sstream>

#include <fmt/format.h>

#include "anvil/io/files.hpp"

namespace anvil {

const MaterialConfig* Config::material(const std::string& name) const {
  for (const auto& m : materials)
    if (m.name == name) return &m;
  return nullptr;
}

int Config::particle_set(const std::string& name) const {
  for (std::size_t i = 0; i < particles.size(); ++i)
    if (particles[i].name == name) return static_cast<int>(i);
  return -1;
}

namespace {

// Whether `s` is well-formed UTF-8 (no overlong forms, surrogates or code points past
// U+10FFFF): deck text is copied into JSON files, which must be UTF-8.
bool is_utf8(std::string_view s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    int len = 0;
    unsigned cp = 0, min = 0;
    if (c < 0x80) {
      ++i;
      continue;
    } else if ((c & 0xE0) == 0xC0) {
      len = 2, cp = c & 0x1Fu, min = 0x80;
    } else if ((c & 0xF0) == 0xE0) {
      len = 3, cp = c & 0x0Fu, min = 0x800;
    } else if ((c & 0xF8) == 0xF0) {
      len = 4, cp = c & 0x07u, min = 0x10000;
    } else {
      return false;
    }
    if (i + static_cast<std::size_t>(len) > s.size()) return false;
    for (int k = 1; k < len; ++k) {
      const auto b = static_cast<unsigned char>(s[i + static_cast<std::size_t>(k)]);
      if ((b & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (b & 0x3Fu);
    }
    if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
    i += static_cast<std::size_t>(len);
  }
  return true;
}

// A YAML node together with the file and key path it was found at, so that every check
// can say where the problem is.
class Node {
public:
  Node(YAML::Node n, std::string path, const std::string* file, int fallback_line)
      : n_(std::move(n)), path_(std::move(path)), file_(file), fallback_line_(fallback_line) {}

  const std::string& path() const { return path_; }
  int line() const {
    // A null value (`gravity:` with nothing after it) is marked at the next token, often on
    // a later line: it is reported at its key's line (QA round 23c).
    if ((!n_ || n_.IsNull()) && fallback_line_ > 0) return fallback_line_;
    const auto m = n_.Mark();
    return m.line >= 0 ? m.line + 1 : fallback_line_;
  }
  SourceLocation where() const { return {*file_, line(), path_}; }
  [[noreturn]] void fail(const std::string& msg) const { throw InputError(where(), msg); }

  bool is_map() const { return n_.IsMap(); }
  bool is_seq() const { return n_.IsSequence(); }
  bool is_scalar() const { return n_.IsScalar(); }
  bool is_null() const { return !n_ || n_.IsNull(); }

  // Children of a map, in file order, after checking the keys against `allowed` (empty:
  // any key) and rejecting duplicates.
  std::vector<std::pair<std::string, Node>>
  entries(std::initializer_list<std::string_view> allowed = {}) const {
    if (!n_.IsMap()) fail("expected a mapping (key: value pairs)");
    std::vector<std::pair<std::string, Node>> out;
    std::set<std::string> seen;
    for (auto it = n_.begin(); it != n_.end(); ++it) {
      const auto key_mark = it->first.Mark();
      const int kline = key_mark.line >= 0 ? key_mark.line + 1 : line();
      if (!it->first.IsScalar())
        throw InputError({*file_, kline, path_}, "keys must be plain names");
      const std::string key = it->first.Scalar();
      if (!is_utf8(key)) throw InputError({*file_, kline, path_}, "a key is not valid UTF-8 text");
      const std::string sub = path_.empty() ? key : path_ + "." + key;
      if (allowed.size() > 0 &&
          std::find(allowed.begin(), allowed.end(), std::string_view(key)) == allowed.end()) {
        std::string list;
        for (auto a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
        throw InputError({*file_, kline, sub},
                         fmt::format("unknown key '{}' (expected one of: {})", key, list));
      }
      if (!seen.insert(key).second) throw InputError({*file_, kline, sub}, "duplicate key");
      out.emplace_back(key, Node(it->second, sub, file_, kline));
    }
    return out;
  }
  void check_keys(std::initializer_list<std::string_view> allowed) const { (void)entries(allowed); }

  bool has(const std::string& key) const { return n_.IsMap() && n_[key]; }
  // The value under `key`; its fallback line (for a value without a mark, or a key
  // missing under it, as in `checkpoint: {}`) is the key's, not this node's.
  Node child(const std::string& key) const {
    int kline = line();
    if (n_.IsMap())
      for (auto it = n_.begin(); it != n_.end(); ++it)
        if (it->first.IsScalar() && it->first.Scalar() == key) {
          if (const auto m = it->first.Mark(); m.line >= 0) kline = m.line + 1;
          break;
        }
    return Node(n_[key], path_.empty() ? key : path_ + "." + key, file_, kline);
  }
  Node required(const std::string& key) const {
    if (!n_.IsMap()) fail("expected a mapping (key: value pairs)");
    // Reported at the line of the key that owns this mapping (the part's name, say).
    if (!has(key))
      throw InputError({*file_, fallback_line_ > 0 ? fallback_line_ : line(),
                        path_.empty() ? key : path_ + "." + key},
                       has("<<") ? "required key is missing (YAML merge keys '<<' are not "
                                   "supported: write the keys out)"
                                 : "required key is missing");
    return child(key);
  }
  std::vector<Node> items() const {
    if (!n_.IsSequence()) fail("expected a list");
    std::vector<Node> out;
    for (std::size_t i = 0; i < n_.size(); ++i)
      out.emplace_back(n_[i], fmt::format("{}[{}]", path_, i), file_, line());
    return out;
  }

  // `true` or `false`.
  bool flag() const {
    const std::string v = str();
    if (v != "true" && v != "false") fail("expected true or false");
    return v == "true";
  }
  bool scalar() const { return n_.IsScalar(); }
  std::string str() const {
    if (!n_.IsScalar()) fail("expected a single value");
    if (!is_utf8(n_.Scalar())) fail("not valid UTF-8 text (save the deck as UTF-8)");
    return n_.Scalar();
  }
  double number() const {
    if (!n_.IsScalar()) fail("expected a number");
    const std::string& s = n_.Scalar();
    // strtod, not stod (which throws on ERANGE): a value below the smallest normal double,
    // 4e-320 say, underflows to a subnormal or to zero, and is a number all the same.
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size() || !std::isfinite(v))
      fail(fmt::format("expected a finite number, got '{}'", s));
    return v;
  }
  std::int64_t integer() const {
    const double v = number();
    if (v != std::floor(v) || std::abs(v) > 9e15)
      fail(fmt::format("expected an integer, got '{}'", str()));
    return static_cast<std::int64_t>(v);
  }
  double positive() const {
    const double v = number();
    if (!(v > 0)) fail(fmt::format("must be positive, got {}", v));
    return v;
  }
  Vec3 vec3() const {
    if (!n_.IsSequence() || n_.size() != 3) fail("expected a list of three numbers [x, y, z]");
    const auto it = items();
    return {it[0].number(), it[1].number(), it[2].number()};
  }
  template <std::size_t N>
  std::array<int, N> positive_ints() const {
    if (!n_.IsSequence() || n_.size() != N)
      fail(fmt::format("expected a list of {} positive integers", N));
    std::array<int, N> out{};
    const auto it = items();
    for (std::size_t i = 0; i < N; ++i) {
      const auto v = it[i].integer();
      if (v < 1 || v > 100000000) it[i].fail("must be a positive integer");
      out[i] = static_cast<int>(v);
    }
    return out;
  }
  int axis() const {
    const std::string s = str();
    if (s == "x") return 0;
    if (s == "y") return 1;
    if (s == "z") return 2;
    fail(fmt::format("axis must be x, y or z, got '{}'", s));
  }
  // A list of components, x, y, z (and a rigid body's rotations rx, ry, rz), or `all` (the
  // six); `rotations` says whether rx, ry or rz is listed by name.
  std::array<bool, 6> components(bool& rotations) const {
    std::array<bool, 6> out{};
    if (n_.IsScalar() && n_.Scalar() == "all") return {true, true, true, true, true, true};
    if (n_.IsScalar())
      fail(fmt::format("expected a list of x, y, z (rx, ry, rz for a rigid part), or all, got "
                       "'{}'",
                       n_.Scalar()));
    const auto list = items();
    if (list.empty()) fail("give at least one of x, y, z (rx, ry, rz for a rigid part), or all");
    for (const auto& c : list) {
      static constexpr std::array<std::string_view, 6> names{"x", "y", "z", "rx", "ry", "rz"};
      const std::string v = c.str();
      const auto it = std::find(names.begin(), names.end(), v);
      if (it == names.end())
        c.fail(fmt::format("expected x, y, z (rx, ry, rz for a rigid part), got '{}'", v));
      const auto k = static_cast<std::size_t>(it - names.begin());
      if (out[k]) c.fail(fmt::format("{} is listed twice", v));
      out[k] = true;
      rotations = rotations || k >= 3;
    }
    return out;
  }

private:
  YAML::Node n_;
  std::string path_;
  const std::string* file_;
  int fallback_line_;
};

// A list of points `[[x0, y0], [x1, y1], ...]`, x strictly increasing, at least one.
void parse_points(const Node& n, std::string_view x_name, std::string_view y_name,
                  std::vector<double>& x, std::vector<double>& y) {
  const auto points = n.items();
  if (points.empty())
    n.fail(fmt::format("expected a list of [{}, {}] points, at least one", x_name, y_name));
  for (const auto& p : points) {
    if (!p.is_seq() || p.items().size() != 2)
      p.fail(fmt::format("expected a point [{}, {}]", x_name, y_name));
    const auto xy = p.items();
    const double xi = xy[0].number();
    if (!x.empty() && !(xi > x.back()))
      xy[0].fail(fmt::format("{}s must increase from point to point: {} follows {}", x_name, xi,
                             x.back()));
    x.push_back(xi);
    y.push_back(xy[1].number());
  }
}

// A time history `[[t0, v0], [t1, v1], ...]`, times strictly increasing.
TimeCurve parse_curve(const Node& n) {
  TimeCurve c;
  parse_points(n, "time", "value", c.t, c.value);
  return c;
}

// Generated meshes define these sets; file meshes define their own (checked at setup).
std::vector<std::string> generated_sets(MeshConfig::Kind kind) {
  switch (kind) {
  case MeshConfig::Kind::box:
    return {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};
  case MeshConfig::Kind::cylinder:
    return {"bottom", "top", "outer"};
  case MeshConfig::Kind::can:
    return {"bottom", "top", "inner", "outer"};
  case MeshConfig::Kind::file:
  case MeshConfig::Kind::embedded:
    return {};
  }
  return {};
}

// A model parameter's value, checked against its admissible range.
double parameter_value(const ParamSpec& spec, const std::string& key, const Node& v) {
  const double x = v.number();
  const bool low_ok = spec.min_exclusive ? x > spec.min : x >= spec.min;
  const bool high_ok = spec.max_exclusive ? x < spec.max : x <= spec.max;
  if (!low_ok || !high_ok) {
    std::string range;
    if (spec.min > -1e299) range += fmt::format("{} {}", spec.min_exclusive ? ">" : ">=", spec.min);
    if (spec.max < 1e299)
      range += fmt::format("{}{} {}", range.empty() ? "" : " and ",
                           spec.max_exclusive ? "<" : "<=", spec.max);
    v.fail(fmt::format("{} = {} is impossible: must be {}", key, x, range));
  }
  return x;
}

// Fills the parameters the deck left out with their defaults; a missing required one is
// an error at `where` (+ prefix + name).
void fill_defaults(std::span<const ParamSpec> specs, ParamValues& values,
                   const SourceLocation& where, const std::string& prefix,
                   const std::string& model) {
  for (const auto& p : specs) {
    if (values.count(std::string(p.name))) continue;
    if (p.required)
      throw InputError({where.file, where.line, where.key + prefix + "." + std::string(p.name)},
                       fmt::format("required parameter of model {} is missing", model));
    values[std::string(p.name)] = p.default_value;
  }
}

// `eos: {model: NAME, params...}` under a material.
void parse_eos(MaterialConfig& m, const Node& n) {
  const std::string model = n.required("model").str();
  const EosModel* info = find_eos_model(model);
  if (!info) {
    std::string list;
    for (const auto& e : eos_models()) list += (list.empty() ? "" : ", ") + std::string(e.name);
    n.child("model").fail(
        fmt::format("unknown equation of state '{}' (available: {})", model, list));
  }
  if (m.model == "ideal_gas") n.fail("an ideal gas has its own equation of state");
  m.eos_model = model;
  for (const auto& [key, v] : n.entries()) {
    if (key == "model") continue;
    const auto spec = std::find_if(info->params.begin(), info->params.end(),
                                   [&key = key](const ParamSpec& p) { return p.name == key; });
    if (spec == info->params.end()) {
      std::string list;
      for (const auto& p : info->params) list += (list.empty() ? "" : ", ") + std::string(p.name);
      v.fail(fmt::format("unknown parameter '{}' for equation of state {} (expected: {})", key,
                         model, list));
    }
    m.eos_params[key] = parameter_value(*spec, key, v);
  }
  fill_defaults(info->params, m.eos_params, n.where(), "", model);
}

MaterialConfig parse_material(const std::string& name, const Node& n) {
  MaterialConfig m;
  m.name = name;
  m.where = n.where();
  const std::string model = n.required("model").str();
  const MaterialModel* info = find_material_model(model);
  if (!info) {
    std::string list;
    for (const auto& mm : material_models())
      list += (list.empty() ? "" : ", ") + std::string(mm.name);
    n.child("model").fail(fmt::format("unknown material model '{}' (available: {})", model, list));
  }
  m.model = model;
  for (const auto& [key, v] : n.entries()) {
    if (key == "model") continue;
    if (key == "eos") {
      parse_eos(m, v);
      continue;
    }
    // A named copy: clang before 16 cannot capture a structured binding in a lambda.
    const std::string& name = key;
    if (const auto table = std::find_if(info->tables.begin(), info->tables.end(),
                                        [&](const TableSpec& t) { return t.name == name; });
        table != info->tables.end()) {
      ParamTable& t = m.tables[key];
      parse_points(v, table->x_name, table->y_name, t.x, t.y);
      continue;
    }
    const auto spec = std::find_if(info->params.begin(), info->params.end(),
                                   [&](const ParamSpec& p) { return p.name == name; });
    if (spec == info->params.end()) {
      std::string list;
      for (const auto& p : info->params) list += (list.empty() ? "" : ", ") + std::string(p.name);
      for (const auto& t : info->tables) list += ", " + std::string(t.name);
      v.fail(fmt::format("unknown parameter '{}' for model {} (expected: {})", key, model, list));
    }
    m.params[key] = parameter_value(*spec, key, v);
  }
  fill_defaults(info->params, m.params, m.where, "", model);
  if (info->check)
    if (const ParamProblem problem = info->check(m.params, m.tables); !problem.why.empty()) {
      // At the table's point, or the key's own line, when the deck gives it; else at the
      // material's.
      if (n.has(problem.key)) {
        const Node key = n.child(problem.key);
        if (problem.point >= 0 && static_cast<std::size_t>(problem.point) < key.items().size())
          key.items()[static_cast<std::size_t>(problem.point)].fail(problem.why);
        key.fail(problem.why);
      }
      throw InputError({m.where.file, m.where.line, m.where.key + "." + problem.key}, problem.why);
    }
  if (m.params.count("youngs_modulus"))
    if (const std::string why = elastic_wave_problem(m.params); !why.empty())
      throw InputError({m.where.file, m.where.line, m.where.key + ".density"}, why);
  return m;
}

// Elements a generator would make (as a double: the product of three divisions of up to
// 1e8 overflows any integer).
double generated_elements(const MeshConfig& mc) {
  switch (mc.kind) {
  case MeshConfig::Kind::box:
    return (mc.box.shape == Shape::tetrahedron ? 6.0
            : mc.box.shape == Shape::wedge     ? 2.0
                                               : 1.0) *
           mc.box.divisions[0] * mc.box.divisions[1] * mc.box.divisions[2];
  case MeshConfig::Kind::cylinder: {
    const double c = std::max(1, mc.cylinder.divisions[0] / 2), n = 2 * c;
    const double ring = mc.cylinder.divisions[0] - c;
    return (n * n + 4 * n * ring) * mc.cylinder.divisions[1];
  }
  case MeshConfig::Kind::can:
    return 1.0 * mc.can.divisions[0] * mc.can.divisions[1] * mc.can.divisions[2];
  case MeshConfig::Kind::file:
  case MeshConfig::Kind::embedded:
    return 0;
  }
  return 0;
}

// Every rank builds the whole mesh, and the generators count in 32-bit integers in places:
// a part is capped well below both limits.
constexpr double max_generated_elements = 1e9;

MeshConfig parse_mesh(const Node& n, const std::string& base_dir) {
  MeshConfig mc;
  mc.where = n.where();
  if (n.has("file")) {
    n.check_keys({"file"});
    mc.kind = MeshConfig::Kind::file;
    std::filesystem::path p(n.child("file").str());
    // (Normal form for messages: "mesh.msh", "../m/a.k", not "./mesh.msh", "m/sub/../a.k".)
    if (p.is_relative()) p = (std::filesystem::path(base_dir) / p).lexically_normal();
    mc.file = p.string();
    if (!std::filesystem::exists(p))
      n.child("file").fail(fmt::format("mesh file '{}' does not exist", mc.file));
    return mc;
  }
  const std::string gen = n.required("generate").str();
  if (gen == "box") {
    n.check_keys({"generate", "min", "max", "divisions", "elements"});
    mc.kind = MeshConfig::Kind::box;
    mc.box.min = n.required("min").vec3();
    mc.box.max = n.required("max").vec3();
    mc.box.divisions = n.required("divisions").positive_ints<3>();
    if (n.has("elements")) {
      const std::string e = n.child("elements").str();
      if (e == "wedges")
        mc.box.shape = Shape::wedge;
      else if (e == "tetrahedra")
        mc.box.shape = Shape::tetrahedron;
      else if (e != "hexahedra")
        n.child("elements")
            .fail(
                fmt::format("unknown elements '{}' (expected hexahedra, wedges or tetrahedra)", e));
    }
    for (int i = 0; i < 3; ++i)
      if (!(mc.box.max[i] > mc.box.min[i]))
        n.child("max").fail("max must exceed min in every direction");
  } else if (gen == "cylinder") {
    n.check_keys({"generate", "radius", "length", "axis", "origin", "divisions"});
    mc.kind = MeshConfig::Kind::cylinder;
    mc.cylinder.radius = n.required("radius").positive();
    mc.cylinder.length = n.required("length").positive();
    if (n.has("axis")) mc.cylinder.axis = n.child("axis").axis();
    if (n.has("origin")) mc.cylinder.origin = n.child("origin").vec3();
    mc.cylinder.divisions = n.required("divisions").positive_ints<2>();
    if (mc.cylinder.divisions[0] < 2)
      n.child("divisions").fail("needs at least 2 elements across the radius");
  } else if (gen == "can") {
    n.check_keys({"generate", "radius", "height", "thickness", "axis", "origin", "divisions"});
    mc.kind = MeshConfig::Kind::can;
    mc.can.radius = n.required("radius").positive();
    mc.can.height = n.required("height").positive();
    mc.can.thickness = n.required("thickness").positive();
    if (mc.can.thickness >= 2 * mc.can.radius)
      n.child("thickness").fail("must be less than the diameter");
    if (n.has("axis")) mc.can.axis = n.child("axis").axis();
    if (n.has("origin")) mc.can.origin = n.child("origin").vec3();
    mc.can.divisions = n.required("divisions").positive_ints<3>();
    if (mc.can.divisions[0] < 3) n.child("divisions").fail("needs at least 3 elements around");
  } else {
    n.child("generate")
        .fail(fmt::format("unknown generator '{}' (expected box, cylinder or can)", gen));
  }
  if (const double count = generated_elements(mc); count > max_generated_elements)
    n.child("divisions")
        .fail(fmt::format("these divisions make {:.3g} elements; a generated part may have at "
                          "most {:.0e}",
                          count, max_generated_elements));
  return mc;
}

PartConfig parse_part(const std::string& name, const Node& n, const std::string& base_dir) {
  PartConfig p;
  p.name = name;
  p.where = n.where();
  n.check_keys({"mesh", "material", "hourglass", "bulk_viscosity", "erosion", "thick_shell",
                "rigid", "merge_with"});
  p.mesh = parse_mesh(n.required("mesh"), base_dir);
  p.material = n.required("material").str();
  if (n.has("rigid")) {
    p.rigid = n.child("rigid").flag();
    // What a rigid part cannot have: its elements do not deform.
    for (const char* key : {"hourglass", "bulk_viscosity", "erosion", "thick_shell"})
      if (p.rigid && n.has(key))
        n.child(key).fail(fmt::format("a rigid part's elements do not deform: {} does not "
                                      "apply",
                                      key));
  }
  if (n.has("merge_with")) {
    p.merge_with = n.child("merge_with").str();
    p.merge_where = n.child("merge_with").where();
    if (p.merge_with.empty())
      n.child("merge_with").fail("give the name of the rigid part whose body this one joins");
    if (!p.rigid)
      n.child("merge_with")
          .fail("merge_with joins a rigid part to another's body: give the part `rigid: true`");
  }
  if (n.has("hourglass")) {
    const Node h = n.child("hourglass");
    h.check_keys({"model", "coefficient"});
    if (h.has("model")) {
      const std::string m = h.child("model").str();
      if (m == "viscous")
        p.hourglass.model = HourglassControl::Model::viscous;
      else if (m == "stiffness")
        p.hourglass.model = HourglassControl::Model::stiffness;
      else if (m == "assumed_strain") {
        p.hourglass.model = HourglassControl::Model::assumed_strain;
        p.hourglass.coefficient = 1.0; // a scale on the physical stiffness
      } else
        h.child("model").fail(fmt::format(
            "unknown hourglass model '{}' (expected viscous, stiffness or assumed_strain)", m));
    }
    if (h.has("coefficient")) {
      const double c = h.child("coefficient").number();
      if (!(c >= 0 && c <= 1)) h.child("coefficient").fail("must be between 0 and 1");
      p.hourglass.coefficient = c;
    }
  }
  if (n.has("thick_shell")) {
    const Node ts = n.child("thick_shell");
    ts.check_keys({"points"});
    const auto pts = ts.required("points").integer();
    if (pts < 2 || pts > ThickShell::max_points)
      ts.child("points").fail(fmt::format("must be between 2 and {}", ThickShell::max_points));
    p.thick_shell.points = static_cast<int>(pts);
    // The element's other hourglass modes take the assumed-strain stiffness.
    if (!n.has("hourglass"))
      p.hourglass = {HourglassControl::Model::assumed_strain, 1.0};
    else if (p.hourglass.model != HourglassControl::Model::assumed_strain)
      n.child("hourglass")
          .fail("a thick_shell part needs hourglass model assumed_strain (its "
                "other hourglass modes take that stiffness)");
  }
  if (n.has("erosion")) {
    const Node er = n.child("erosion");
    er.check_keys({"plastic_strain", "inverted"});
    if (er.has("plastic_strain")) p.erosion.plastic_strain = er.child("plastic_strain").positive();
    if (er.has("inverted")) {
      p.erosion.inverted = er.child("inverted").flag();
    }
  }
  if (n.has("bulk_viscosity")) {
    const Node b = n.child("bulk_viscosity");
    b.check_keys({"linear", "quadratic"});
    if (b.has("linear")) p.bulk_viscosity.linear = b.child("linear").number();
    if (b.has("quadratic")) p.bulk_viscosity.quadratic = b.child("quadratic").number();
    if (p.bulk_viscosity.linear < 0) b.child("linear").fail("must not be negative");
    if (p.bulk_viscosity.quadratic < 0) b.child("quadratic").fail("must not be negative");
  }
  return p;
}

// One particle set: `generate: {shape: box|sphere|cylinder, ..., spacing: s}` and the
// formulation's options (docs/sph.md).
// `dimensions`: the deck's sph.dimensions (3 unless it gives 1 or 2), for the lattice's size.
ParticleSetConfig parse_particle_set(const std::string& name, const Node& n, int dimensions) {
  ParticleSetConfig p;
  p.name = name;
  p.where = n.where();
  n.check_keys({"generate", "material", "smoothing_ratio", "smoothing_length", "smoothing_bounds",
                "kernel", "viscosity", "artificial_stress", "corrected_gradient",
                "summation_density"});
  const Node g = n.required("generate");
  const std::string shape = g.required("shape").str();
  LatticeSpec& l = p.lattice;
  if (shape == "box") {
    g.check_keys({"shape", "min", "max", "spacing"});
    l.shape = LatticeSpec::Shape::box;
    l.min = g.required("min").vec3();
    l.max = g.required("max").vec3();
    for (int i = 0; i < 3; ++i)
      if (!(l.max[i] > l.min[i])) g.child("max").fail("max must exceed min in every direction");
  } else if (shape == "sphere") {
    g.check_keys({"shape", "center", "radius", "spacing"});
    l.shape = LatticeSpec::Shape::sphere;
    l.center = g.required("center").vec3();
    l.radius = g.required("radius").positive();
  } else if (shape == "cylinder") {
    g.check_keys({"shape", "origin", "radius", "inner_radius", "length", "axis", "spacing"});
    l.shape = LatticeSpec::Shape::cylinder;
    if (g.has("origin")) l.origin = g.child("origin").vec3();
    l.radius = g.required("radius").positive();
    l.length = g.required("length").positive();
    if (g.has("axis")) l.axis = g.child("axis").axis();
    if (g.has("inner_radius")) {
      l.inner_radius = g.child("inner_radius").number();
      if (!(l.inner_radius >= 0 && l.inner_radius < l.radius))
        g.child("inner_radius").fail("must be at least 0 and less than the radius");
    }
  } else {
    g.child("shape").fail(
        fmt::format("unknown particle shape '{}' (expected box, sphere or cylinder)", shape));
  }
  l.spacing = g.required("spacing").positive();
  // A lattice of more than 2^31 particles on one deck line is a typo, not a model. (An
  // upper bound: the shape's extents along the model's dimensions, x, then y, then z.)
  const double round = 2 * std::max(l.radius, l.length);
  const Vec3 extent = shape == "box"      ? l.max - l.min
                      : shape == "sphere" ? Vec3{2 * l.radius, 2 * l.radius, 2 * l.radius}
                                          : Vec3{round, round, round};
  double cells = 1;
  for (int i = 0; i < dimensions; ++i) cells *= extent[i] / l.spacing;
  if (cells > 2e9) g.child("spacing").fail("the lattice would hold more than 2e9 particles");
  p.material = n.required("material").str();
  if (n.has("smoothing_ratio")) {
    p.smoothing_ratio = n.child("smoothing_ratio").positive();
    if (p.smoothing_ratio < 0.8 || p.smoothing_ratio > 3)
      n.child("smoothing_ratio")
          .fail("must be between 0.8 and 3 (h = ratio * (cell volume)^(1/dimensions))");
  }
  if (n.has("smoothing_length")) {
    if (n.has("smoothing_ratio"))
      n.child("smoothing_length")
          .fail("give smoothing_ratio or smoothing_length, not both (the length is h0 itself)");
    p.smoothing_length = n.child("smoothing_length").positive();
    // The same bounds as the ratio's, against the lattice spacing.
    const double ratio = p.smoothing_length / l.spacing;
    if (ratio < 0.8 || ratio > 3)
      n.child("smoothing_length")
          .fail(fmt::format("is {:.6g} times the spacing; it must be between 0.8 and 3 times",
                            ratio));
  }
  if (n.has("smoothing_bounds")) {
    const Node b = n.child("smoothing_bounds");
    if (!b.is_seq() || b.items().size() != 2)
      b.fail("expected a list of two numbers [min, max], the bounds of h / h0");
    const auto it = b.items();
    p.h_min = it[0].positive();
    p.h_max = it[1].positive();
    if (p.h_min > 1) it[0].fail(fmt::format("must not exceed 1 (h0 itself), got {}", p.h_min));
    if (p.h_max < 1) it[1].fail(fmt::format("must be at least 1 (h0 itself), got {}", p.h_max));
  }
  if (n.has("kernel")) {
    const std::string k = n.child("kernel").str();
    if (k == "cubic_spline")
      p.kernel = ParticleSetConfig::Kernel::cubic_spline;
    else if (k == "wendland_c2")
      p.kernel = ParticleSetConfig::Kernel::wendland_c2;
    else
      n.child("kernel").fail(
          fmt::format("unknown kernel '{}' (expected cubic_spline or wendland_c2)", k));
  }
  if (n.has("viscosity")) {
    const Node v = n.child("viscosity");
    v.check_keys({"linear", "quadratic"});
    if (v.has("linear")) p.viscosity_linear = v.child("linear").number();
    if (v.has("quadratic")) p.viscosity_quadratic = v.child("quadratic").number();
    if (p.viscosity_linear < 0) v.child("linear").fail("must not be negative");
    if (p.viscosity_quadratic < 0) v.child("quadratic").fail("must not be negative");
  }
  if (n.has("artificial_stress")) {
    const Node a = n.child("artificial_stress");
    a.check_keys({"epsilon", "exponent"});
    if (a.has("epsilon")) p.artificial_stress = a.child("epsilon").number();
    if (a.has("exponent")) p.artificial_stress_exponent = a.child("exponent").number();
    if (p.artificial_stress < 0 || p.artificial_stress > 1)
      a.child("epsilon").fail("must be between 0 and 1");
    if (p.artificial_stress_exponent < 1 || p.artificial_stress_exponent > 8)
      a.child("exponent").fail("must be between 1 and 8");
  }
  if (n.has("corrected_gradient")) {
    p.corrected_gradient = n.child("corrected_gradient").flag();
  }
  if (n.has("summation_density")) {
    p.summation_density = n.child("summation_density").flag();
  }
  return p;
}

Box3 parse_box(const Node& n) {
  n.check_keys({"min", "max"});
  Box3 b{n.required("min").vec3(), n.required("max").vec3()};
  for (int i = 0; i < 3; ++i)
    if (b.hi[i] < b.lo[i]) n.child("max").fail("max must not be below min");
  return b;
}

// An inline selection {part, box} (either or both).
Selection parse_inline_selection(const Node& n) {
  Selection s;
  s.where = n.where();
  n.check_keys({"part", "box"});
  if (n.has("part")) s.part = n.child("part").str();
  if (n.has("box")) s.box = parse_box(n.child("box"));
  if (!s.part && !s.box) n.fail("a selection needs a part, a box, or both");
  return s;
}

// `birth` and `death` (s) of a timed condition or load: 0 <= birth < death.
void parse_window(const Node& n, double& birth, double& death) {
  if (n.has("birth")) {
    birth = n.child("birth").number();
    if (birth < 0) n.child("birth").fail("must not be negative");
  }
  if (n.has("death")) {
    death = n.child("death").number();
    if (!(death > birth)) n.child("death").fail(fmt::format("must be after the birth ({})", birth));
  }
}

// A set reference: a name, or an inline selection.
Selection parse_set_ref(const Node& n) {
  if (n.is_map()) return parse_inline_selection(n);
  Selection s;
  s.name = n.str();
  s.where = n.where();
  return s;
}

// The 1-based line of the last document marker ('---' or '...') at or before the 0-based
// line `upto` (where yaml-cpp puts the next document), or `upto` + 1 if there is none.
int separator_line(const std::string& text, int upto) {
  std::istringstream in(text);
  std::string l;
  int found = upto + 1;
  for (int i = 0; i <= upto && std::getline(in, l); ++i)
    if (l.rfind("---", 0) == 0 || l.rfind("...", 0) == 0) found = i + 1;
  return found;
}

// A name the deck defines (part, particle set, node set): not empty, and without '.'
// (PART.SET names a set of a part's mesh: a name with a dot could hide one).
void check_defined_name(const Node& n, const std::string& name, const char* what) {
  if (name.empty()) n.fail(fmt::format("{} names may not be empty", what));
  if (name.find('.') != std::string::npos)
    n.fail(
        fmt::format("{} names may not contain '.' (PART.SET names a set of a part's mesh)", what));
}

// Sees the documents of a YAML stream: where the second starts, and whether it holds
// anything (a lone '---' at the end holds nothing).
class SecondDocument : public YAML::EventHandler {
public:
  int line = -1;        // 0-based line of the second document's start
  bool content = false; // it holds a node
  void OnDocumentStart(const YAML::Mark& m) override {
    if (++docs_ == 2) line = m.line;
  }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override { seen(); }
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t,
                const std::string&) override {
    seen();
  }
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    seen();
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    seen();
  }
  void OnMapEnd() override {}

private:
  int docs_ = 0;
  void seen() { content |= docs_ == 2; }
};

} // namespace

std::vector<int> rigid_body_leads(const std::vector<PartConfig>& parts) {
  std::vector<int> lead(parts.size(), -1);
  for (std::size_t p = 0; p < parts.size(); ++p) {
    if (!parts[p].rigid) continue;
    std::size_t q = p;
    for (std::size_t hops = 0; !parts[q].merge_with.empty() && hops < parts.size(); ++hops) {
      const auto it = std::find_if(parts.begin(), parts.end(), [&](const PartConfig& c) {
        return c.name == parts[q].merge_with;
      });
      if (it == parts.end()) break;
      q = static_cast<std::size_t>(it - parts.begin());
    }
    lead[p] = static_cast<int>(q);
  }
  return lead;
}

void check_rigid_merges(const std::vector<PartConfig>& parts) {
  for (const PartConfig& p : parts) {
    if (p.merge_with.empty()) continue;
    const auto it = std::find_if(parts.begin(), parts.end(),
                                 [&](const PartConfig& c) { return c.name == p.merge_with; });
    if (it == parts.end())
      throw InputError(p.merge_where,
                       fmt::format("part '{}' is not defined under parts", p.merge_with));
    if (!it->rigid)
      throw InputError(p.merge_where,
                       fmt::format("part '{}' is not rigid: a rigid part merges into another "
                                   "rigid part's body",
                                   p.merge_with));
  }
  // (Every target exists now.) Following the chain must end at a part of its own body.
  for (const PartConfig& p : parts) {
    const PartConfig* q = &p;
    for (std::size_t hops = 0; !q->merge_with.empty(); ++hops) {
      if (hops >= parts.size())
        throw InputError(p.merge_where,
                         fmt::format("part '{}' merges into a chain of parts that comes back to "
                                     "itself: one part of a body must merge into none (the lead)",
                                     p.name));
      q = &*std::find_if(parts.begin(), parts.end(),
                         [&](const PartConfig& c) { return c.name == q->merge_with; });
    }
  }
}

Config parse_deck(const std::string& text, const std::string& name, const std::string& base_dir) {
  Config c;
  c.deck_file = name;
  YAML::Node root;
  try {
    root = YAML::Load(text); // the first document
    // A second document would be dropped without a word: everything after a '---' or
    // '...' line. It is reported at that line. (The parser is asked for two documents at
    // most: YAML::LoadAll did not return on some malformed input, found by fuzzing.)
    std::istringstream in(text);
    YAML::Parser parser(in);
    SecondDocument second;
    if (parser.HandleNextDocument(second) && parser.HandleNextDocument(second) && second.content)
      throw InputError({name, separator_line(text, second.line), ""},
                       "a deck holds one YAML document; a second one starts here (remove the "
                       "'---' or '...' line)");
  } catch (const YAML::DeepRecursion& e) {
    throw InputError({name, e.mark.line >= 0 ? e.mark.line + 1 : 0, ""},
                     "malformed YAML: nested too deep");
  } catch (const YAML::Exception& e) {
    throw InputError({name, e.mark.line >= 0 ? e.mark.line + 1 : 0, ""},
                     "malformed YAML: " + e.msg);
  }
  const Node top(root, "", &c.deck_file, 1);
  if (top.is_null()) throw InputError({name, 1, ""}, "the deck is empty");
  const auto entries = top.entries({"title", "termination", "time_step", "materials", "parts",
                                    "particles", "sph", "node_sets", "initial_conditions",
                                    "boundary_conditions", "contact", "rigid_walls", "gravity",
                                    "loads", "probes", "output", "checkpoint", "decomposition"});
  (void)entries;

  if (top.has("title")) c.title = top.child("title").str();

  const Node term = top.required("termination");
  term.check_keys({"time", "cycles"});
  if (!term.has("time") && !term.has("cycles"))
    term.fail("give an end time, a number of cycles, or both");
  if (term.has("time")) c.end_time = term.child("time").positive();
  if (term.has("cycles")) {
    c.end_cycles = term.child("cycles").integer();
    // (0 would end the run before its first step; LS-DYNA's ENDCYC 0 means "no limit",
    // which here is leaving `cycles` out.)
    if (c.end_cycles < 1)
      term.child("cycles").fail("must be at least 1 (leave cycles out for no cycle limit)");
  }

  if (top.has("time_step")) {
    const Node ts = top.child("time_step");
    ts.check_keys({"scale", "minimum_fraction", "mass_scaling"});
    if (ts.has("mass_scaling")) {
      const Node ms = ts.child("mass_scaling");
      ms.check_keys({"step"});
      if (!ms.has("step")) ms.fail("give `step`: the time step the run starts with, s");
      c.mass_scaling_step = ms.child("step").positive();
      c.mass_scaling_where = ms.child("step").where();
    }
    if (ts.has("minimum_fraction")) {
      c.time_step_minimum_fraction = ts.child("minimum_fraction").number();
      if (!(c.time_step_minimum_fraction >= 0 && c.time_step_minimum_fraction < 1))
        ts.child("minimum_fraction").fail("must be in [0, 1): a fraction of the initial time step");
    }
    if (ts.has("scale")) {
      c.time_step_scale = ts.child("scale").number();
      if (!(c.time_step_scale > 0 && c.time_step_scale <= 1))
        ts.child("scale").fail("must be in (0, 1]: a fraction of the stable time step");
    }
  }

  for (const auto& [mname, mn] : top.required("materials").entries())
    c.materials.push_back(parse_material(mname, mn));
  if (c.materials.empty()) top.child("materials").fail("at least one material is needed");

  // Finite-element parts; a deck of particles only needs none.
  if (top.has("parts") || !top.has("particles")) {
    for (const auto& [pname, pn] : top.required("parts").entries()) {
      check_defined_name(pn, pname, "part");
      PartConfig p = parse_part(pname, pn, base_dir);
      const MaterialConfig* mat = c.material(p.material);
      if (!mat)
        pn.child("material")
            .fail(fmt::format("material '{}' is not defined under materials", p.material));
      // A fluid has no shear stiffness for the hexahedra's hourglass control.
      if (mat->model == "fluid")
        pn.child("material")
            .fail(fmt::format("material '{}' is a fluid (no shear stiffness): it is available "
                              "to particles only",
                              p.material));
      // The hexahedra do not track specific internal energy (docs/sph.md).
      if (mat->model == "ideal_gas" || !mat->eos_model.empty())
        pn.child("material")
            .fail(fmt::format("material '{}' needs the specific internal energy ({}): it is "
                              "available to particles only",
                              p.material, mat->eos_model.empty() ? "ideal gas" : "eos"));
      c.parts.push_back(std::move(p));
    }
    if (c.parts.empty() && !top.has("particles"))
      top.child("parts").fail("at least one part is needed");
    check_rigid_merges(c.parts);
  }

  if (top.has("particles")) {
    // (sph.dimensions is checked below; here only to size the lattices.)
    int dimensions = 3;
    if (top.has("sph") && top.child("sph").has("dimensions")) {
      const std::int64_t d = top.child("sph").child("dimensions").integer();
      if (d == 1 || d == 2) dimensions = static_cast<int>(d);
    }
    for (const auto& [pname, pn] : top.child("particles").entries()) {
      check_defined_name(pn, pname, "particle set");
      if (std::any_of(c.parts.begin(), c.parts.end(),
                      [&pname = pname](const PartConfig& p) { return p.name == pname; }))
        pn.fail(fmt::format("'{}' is already the name of a part", pname));
      ParticleSetConfig p = parse_particle_set(pname, pn, dimensions);
      if (!c.material(p.material))
        pn.child("material")
            .fail(fmt::format("material '{}' is not defined under materials", p.material));
      c.particles.push_back(std::move(p));
    }
    if (c.particles.empty() && c.parts.empty())
      top.child("particles").fail("at least one particle set (or a part) is needed");
  }
  if (top.has("sph")) {
    const Node s = top.child("sph");
    s.check_keys({"rebalance_threshold", "dimensions"});
    if (s.has("dimensions")) {
      const auto d = s.child("dimensions").integer();
      if (d < 1 || d > 3) s.child("dimensions").fail("must be 1, 2 or 3");
      if (d < 3 && !c.parts.empty())
        s.child("dimensions")
            .fail("a particle model of fewer than 3 dimensions cannot be coupled to the mesh");
      for (const auto& p : c.particles)
        if (d == 1 && p.kernel == ParticleSetConfig::Kernel::wendland_c2)
          s.child("dimensions").fail("wendland_c2 is available in 2 and 3 dimensions");
      c.sph.dimensions = static_cast<int>(d);
    }
    if (s.has("rebalance_threshold")) {
      c.sph.rebalance_threshold = s.child("rebalance_threshold").number();
      if (!(c.sph.rebalance_threshold >= 1))
        s.child("rebalance_threshold").fail("must be at least 1");
    }
  }

  if (top.has("decomposition")) {
    const Node d = top.child("decomposition");
    d.check_keys({"fe", "scale"});
    if (d.has("fe")) {
      const std::string m = d.child("fe").str();
      if (m == "metis")
        c.decomposition.fe = DecompositionConfig::Fe::metis;
      else if (m == "rcb")
        c.decomposition.fe = DecompositionConfig::Fe::rcb;
      else
        d.child("fe").fail(fmt::format("unknown FE decomposition '{}' (metis or rcb)", m));
    }
    if (d.has("scale")) {
      c.decomposition.scale = d.child("scale").vec3();
      for (int i = 0; i < 3; ++i)
        if (!(c.decomposition.scale[i] > 0 && std::isfinite(c.decomposition.scale[i])))
          d.child("scale").fail("each factor must be positive (a stretch of x, y, z)");
    }
  }

  // A part name may also name a particle set (selections, probes).
  auto part_exists = [&](const std::string& n) {
    return std::any_of(c.parts.begin(), c.parts.end(),
                       [&](const PartConfig& p) { return p.name == n; }) ||
           c.particle_set(n) >= 0;
  };
  auto check_part = [&](const Selection& s) {
    if (s.part && !part_exists(*s.part))
      throw InputError({s.where.file, s.where.line, s.where.key + ".part"},
                       fmt::format("part '{}' is not defined under parts or particles", *s.part));
  };
  // Named sets: deck sets, then PART.SET of generated meshes; file meshes are checked
  // once read.
  auto check_name = [&](const Selection& s) {
    if (s.name.empty()) return check_part(s);
    if (c.node_sets.count(s.name)) return;
    const auto dot = s.name.find('.');
    if (dot != std::string::npos) {
      const std::string part = s.name.substr(0, dot), set = s.name.substr(dot + 1);
      for (const auto& p : c.parts)
        if (p.name == part) {
          if (p.mesh.kind == MeshConfig::Kind::file) return;
          const auto sets = generated_sets(p.mesh.kind);
          if (std::find(sets.begin(), sets.end(), set) != sets.end()) return;
          std::string list;
          for (const auto& x : sets) list += (list.empty() ? "" : ", ") + part + "." + x;
          throw InputError(s.where, fmt::format("node set '{}' does not exist: part '{}' has {}",
                                                s.name, part, list));
        }
    }
    throw InputError(
        s.where,
        fmt::format("node set '{}' is not defined (define it under node_sets, or use PART.SET)",
                    s.name));
  };

  if (top.has("node_sets")) {
    for (const auto& [sname, sn] : top.child("node_sets").entries()) {
      check_defined_name(sn, sname, "node set");
      Selection s = parse_inline_selection(sn);
      s.name.clear();
      check_part(s);
      c.node_sets[sname] = s;
    }
  }

  // The nodes an initial or boundary condition acts on: `part: P` (all of P's; the item's
  // key, where check_part and the model name the `part` key under it) or `set: S`.
  auto parse_target = [&](const Node& n) {
    if (n.has("part") == n.has("set")) n.fail("give exactly one of 'part' or 'set'");
    Selection s;
    if (n.has("part")) {
      s.part = n.child("part").str();
      s.where = {c.deck_file, n.child("part").line(), n.path()};
    } else {
      s = parse_set_ref(n.child("set"));
    }
    check_name(s);
    return s;
  };

  if (top.has("initial_conditions")) {
    for (const auto& n : top.child("initial_conditions").items()) {
      n.check_keys({"part", "set", "velocity", "angular_velocity", "center"});
      InitialCondition ic;
      ic.where = n.where();
      ic.nodes = parse_target(n);
      if (!n.has("velocity") && !n.has("angular_velocity"))
        n.fail("give a velocity, an angular_velocity, or both");
      if (n.has("velocity")) ic.velocity = n.child("velocity").vec3();
      if (n.has("angular_velocity")) {
        ic.angular_velocity = n.child("angular_velocity").vec3();
        const Node centre = n.required("center");
        if (centre.scalar()) {
          if (centre.str() != "mass_center")
            centre.fail("expected a point [x, y, z] or mass_center (the centre of mass of the "
                        "nodes it sets)");
          ic.about_mass_center = true;
        } else {
          ic.center = centre.vec3();
        }
      } else if (n.has("center")) {
        n.child("center").fail("center is only used with angular_velocity");
      }
      c.initial_conditions.push_back(ic);
    }
  }

  if (top.has("boundary_conditions")) {
    for (const auto& n : top.child("boundary_conditions").items()) {
      n.check_keys({"set", "part", "fix", "velocity", "displacement", "angular_velocity",
                    "rotation", "curve", "components", "birth", "death"});
      BoundaryCondition bc;
      bc.where = n.where();
      parse_window(n, bc.birth, bc.death);
      bc.nodes = parse_target(n);
      // The spin of a rigid part: its rate (`angular_velocity`, with a velocity), or its
      // angle (`rotation`, radians about the global axes, with a displacement: the body
      // turns by the curve's change each step).
      const bool turned = n.has("rotation");
      const bool spun = n.has("angular_velocity") || turned;
      const char* spin_key = turned ? "rotation" : "angular_velocity";
      if (n.has("velocity") && n.has("displacement"))
        n.fail("give exactly one of 'fix', 'velocity' or 'displacement'");
      if (turned && n.has("angular_velocity"))
        n.child("rotation").fail("give angular_velocity (a rate) or rotation (an angle), not both");
      if (n.has("displacement") && n.has("angular_velocity"))
        n.child("angular_velocity")
            .fail("angular_velocity goes with velocity; with a displacement, give the angle: "
                  "rotation");
      if (n.has("velocity") && turned)
        n.child("rotation")
            .fail("rotation (an angle) goes with displacement; with a velocity, give the rate: "
                  "angular_velocity");
      if (int(n.has("fix")) + int(n.has("velocity") || n.has("displacement") || spun) != 1)
        n.fail("give exactly one of 'fix', 'velocity' (and/or 'angular_velocity' for a rigid "
               "part) or 'displacement' (and/or 'rotation')");
      if (n.has("fix")) {
        const auto held = n.child("fix").components(bc.rotations);
        for (std::size_t i = 0; i < 3; ++i) {
          bc.fix[i] = held[i];
          bc.fix_spin[i] = held[3 + i];
        }
        for (const char* key : {"components", "curve"})
          if (n.has(key))
            n.child(key).fail(fmt::format(
                "{} goes with velocity or displacement; list fixed components under fix", key));
      } else {
        bc.prescribed = true;
        const bool moved = n.has("displacement") || turned;
        bc.motion =
            moved ? BoundaryCondition::Motion::displacement : BoundaryCondition::Motion::velocity;
        // Whether a translation (of the nodes, or of a rigid body's centre) is given.
        const bool moving = n.has("displacement") || n.has("velocity");
        if (moving) bc.value = n.child(n.has("displacement") ? "displacement" : "velocity").vec3();
        if (spun) {
          bc.spin = n.child(spin_key).vec3();
          bc.rotations = true;
        }
        if (n.has("components")) {
          bool listed_rotations = false;
          const auto held = n.child("components").components(listed_rotations);
          bc.rotations = bc.rotations || listed_rotations;
          for (std::size_t i = 0; i < 3; ++i) {
            bc.components[i] = held[i] && moving;
            bc.spin_components[i] = held[3 + i] && spun;
            if (held[i] && !moving)
              n.child("components")
                  .fail(fmt::format("{} is listed, but no velocity or displacement is given",
                                    "xyz"[i]));
            if (held[3 + i] && !spun)
              n.child("components")
                  .fail(fmt::format("r{} is listed, but no angular_velocity or rotation is given",
                                    "xyz"[i]));
          }
        } else {
          bc.components = {moving, moving, moving};
          bc.spin_components = {spun, spun, spun};
        }
        // A value on a component the condition leaves free would be dropped: a driver
        // meant to move along x that holds only z would stand still in x (QA round 24).
        for (std::size_t i = 0; i < 3; ++i) {
          if (moving && !bc.components[i] && bc.value[static_cast<int>(i)] != 0)
            n.child(n.has("displacement") ? "displacement" : "velocity")
                .fail(fmt::format("{} on {}, which `components` leaves out: list {} there, or "
                                  "give 0",
                                  bc.value[static_cast<int>(i)], "xyz"[i], "xyz"[i]));
          if (spun && !bc.spin_components[i] && bc.spin[static_cast<int>(i)] != 0)
            n.child(spin_key).fail(
                fmt::format("{} about {}, which `components` leaves out: list r{} there, "
                            "or give 0",
                            bc.spin[static_cast<int>(i)], "xyz"[i], "xyz"[i]));
        }
        if (n.has("curve")) bc.curve = parse_curve(n.child("curve"));
        if (moved && !bc.curve)
          n.fail(fmt::format("a {} needs its time history: add curve: [[t0, 0], [t1, 1], ...]",
                             turned && !n.has("displacement") ? "rotation" : "displacement"));
        if (bc.curve) {
          const double amplitude =
              std::max({std::abs(bc.value.x), std::abs(bc.value.y), std::abs(bc.value.z),
                        std::abs(bc.spin.x), std::abs(bc.spin.y), std::abs(bc.spin.z)});
          if (const auto problem = time_history_problem(amplitude, *bc.curve, moved);
              !problem.empty())
            n.child("curve").fail(problem);
        }
      }
      c.boundary_conditions.push_back(bc);
    }
  }

  if (top.has("probes")) {
    std::set<std::string> names;
    for (const auto& n : top.child("probes").items()) {
      n.check_keys({"name", "at", "element_at"});
      const bool element = n.has("element_at");
      if (element == n.has("at"))
        n.fail("a probe needs a point: `at` (the nearest node or particle) or `element_at` (the "
               "element whose centroid is nearest), one of them");
      ProbeConfig p{n.required("name").str(), n.required(element ? "element_at" : "at").vec3(),
                    n.where()};
      // The name heads history.csv columns (NAME.ux): no commas, quotes or blanks.
      const auto plain = [](char ch) {
        return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
               ch == '_' || ch == '.' || ch == '-';
      };
      if (p.name.empty() || !std::all_of(p.name.begin(), p.name.end(), plain))
        n.child("name").fail(fmt::format(
            "probe name '{}' must be a plain name: letters, digits, '_', '.' and '-'", p.name));
      if (!names.insert(p.name).second)
        n.child("name").fail(fmt::format("probe name '{}' is used twice", p.name));
      (element ? c.element_probes : c.probes).push_back(p);
    }
  }

  if (top.has("contact")) {
    const auto items = top.child("contact").items();
    if (items.size() > 1)
      items[1].fail("one contact definition is supported (general contact among its parts)");
    for (const auto& n : items) {
      n.check_keys(
          {"type", "parts", "penalty_scale", "friction", "depth_fraction", "rebalance_threshold"});
      ContactConfig cc;
      cc.where = n.where();
      const std::string type = n.has("type") ? n.child("type").str() : "general";
      if (type != "general")
        n.child("type").fail(fmt::format("unknown contact type '{}' (expected general)", type));
      if (n.has("parts")) {
        const Node p = n.child("parts");
        if (!(p.is_scalar() && p.str() == "all")) {
          if (!p.is_seq()) // (QA round 17: `parts: a` said only "expected a list")
            p.fail(fmt::format("give a list of parts or 'all', got '{}' (write [{}] for one part)",
                               p.is_scalar() ? p.str() : std::string("a map"),
                               p.is_scalar() ? p.str() : std::string("NAME")));
          for (const auto& it : p.items()) {
            const std::string name = it.str();
            if (!part_exists(name))
              it.fail(fmt::format("part '{}' is not defined under parts or particles", name));
            if (std::find(cc.parts.begin(), cc.parts.end(), name) != cc.parts.end())
              it.fail(fmt::format("part '{}' is listed twice", name));
            cc.parts.push_back(name);
          }
          if (cc.parts.empty()) p.fail("give a list of parts or 'all'");
        }
      }
      if (n.has("penalty_scale")) cc.penalty_scale = n.child("penalty_scale").positive();
      if (n.has("friction")) {
        cc.friction = n.child("friction").number();
        if (cc.friction < 0) n.child("friction").fail("must not be negative");
      }
      if (n.has("depth_fraction")) {
        cc.depth_fraction = n.child("depth_fraction").positive();
        if (cc.depth_fraction > 1)
          n.child("depth_fraction").fail("must be at most 1 (an element depth)");
      }
      if (n.has("rebalance_threshold")) {
        cc.rebalance_threshold = n.child("rebalance_threshold").number();
        if (!(cc.rebalance_threshold >= 1))
          n.child("rebalance_threshold").fail("must be at least 1");
      }
      c.contact.push_back(cc);
    }
  }

  // gravity: [gx, gy, gz], or {acceleration: [..], curve: [[t, s], ...]}.
  if (top.has("gravity")) {
    const Node g = top.child("gravity");
    BodyLoad load;
    load.where = g.where();
    if (g.is_map()) {
      g.check_keys({"acceleration", "curve"});
      load.acceleration = g.required("acceleration").vec3();
      if (g.has("curve")) {
        load.curve = parse_curve(g.child("curve"));
        const Vec3& a = load.acceleration;
        const double amplitude = std::max({std::abs(a.x), std::abs(a.y), std::abs(a.z)});
        if (const auto problem = time_history_problem(amplitude, *load.curve, false);
            !problem.empty())
          g.child("curve").fail(problem);
      }
    } else {
      load.acceleration = g.vec3();
    }
    c.body_loads.push_back(load);
  }

  // loads: forces on nodes, pressures on faces, each optionally times a time history.
  if (top.has("loads")) {
    for (const auto& n : top.child("loads").items()) {
      n.check_keys({"set", "force", "surface", "pressure", "curve", "birth", "death"});
      Load load;
      load.where = n.where();
      parse_window(n, load.birth, load.death);
      if (n.has("force") == n.has("pressure")) n.fail("give exactly one of 'force' or 'pressure'");
      double amplitude = 0;
      if (n.has("force")) {
        load.kind = Load::Kind::force;
        if (n.has("surface"))
          n.child("surface").fail("a force acts on the nodes of a set: write set, not surface");
        load.target = parse_set_ref(n.required("set"));
        load.force = n.child("force").vec3();
        amplitude =
            std::max({std::abs(load.force.x), std::abs(load.force.y), std::abs(load.force.z)});
      } else {
        load.kind = Load::Kind::pressure;
        if (n.has("set")) n.child("set").fail("a pressure acts on faces: write surface, not set");
        load.target = parse_set_ref(n.required("surface"));
        load.pressure = n.child("pressure").number();
        amplitude = std::abs(load.pressure);
      }
      check_name(load.target);
      if (n.has("curve")) {
        load.curve = parse_curve(n.child("curve"));
        if (const auto problem = time_history_problem(amplitude, *load.curve, false);
            !problem.empty())
          n.child("curve").fail(problem);
      }
      c.loads.push_back(load);
    }
  }

  if (top.has("rigid_walls")) {
    for (const auto& n : top.child("rigid_walls").items()) {
      n.check_keys({"point", "normal", "friction"});
      RigidWallConfig w;
      w.where = n.where();
      w.point = n.required("point").vec3();
      Vec3 nrm = n.required("normal").vec3();
      // Scaled by its largest component first: the norm of [1e-200, 0, 1e-200] underflows.
      const double big = std::max({std::abs(nrm.x), std::abs(nrm.y), std::abs(nrm.z)});
      if (!(big > 0)) n.child("normal").fail("the normal must not be zero");
      nrm = {nrm.x / big, nrm.y / big, nrm.z / big};
      w.normal = nrm * (1 / norm(nrm));
      if (n.has("friction")) {
        w.friction = n.child("friction").number();
        if (w.friction < 0) n.child("friction").fail("must not be negative");
      }
      c.rigid_walls.push_back(w);
    }
  }

  if (top.has("checkpoint")) {
    const Node cp = top.child("checkpoint");
    cp.check_keys({"every", "cycles"});
    if (!cp.has("every") && !cp.has("cycles"))
      cp.fail("`every` (seconds of simulated time) or `cycles` is missing: give either or both");
    if (cp.has("every")) c.checkpoint_every = cp.child("every").positive();
    if (cp.has("cycles")) {
      c.checkpoint_every_cycles = cp.child("cycles").integer();
      if (c.checkpoint_every_cycles < 1) cp.child("cycles").fail("must be at least 1");
    }
  }

  if (top.has("output")) {
    const Node o = top.child("output");
    o.check_keys({"fields_every", "history_every", "format", "part_energies"});
    if (o.has("part_energies")) c.part_energies = o.child("part_energies").flag();
    if (o.has("fields_every")) c.fields_every = o.child("fields_every").positive();
    if (o.has("history_every")) c.history_every = o.child("history_every").positive();
    if (o.has("format")) {
      const std::string f = o.child("format").str();
      if (f == "vtu")
        c.output_format = OutputFormat::vtu;
      else if (f == "exodus")
        c.output_format = OutputFormat::exodus;
      else if (f == "both")
        c.output_format = OutputFormat::both;
      else
        o.child("format").fail(
            fmt::format("unknown output format '{}' (expected vtu, exodus or both)", f));
    }
  }
  return c;
}

Config read_deck(const std::string& path) {
  // A YAML deck holds no mesh: anything near this size is not a deck (/dev/zero, a log).
  constexpr std::uintmax_t max_deck_bytes = std::uintmax_t{64} << 20;
  const std::string text = read_input_file(path, max_deck_bytes);
  const auto dir = std::filesystem::path(path).parent_path();
  return parse_deck(text, path, dir.empty() ? "." : dir.string());
}

} // namespace anvil
