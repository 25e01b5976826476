// Constitutive models behind one interface that works on batches of material points
// (element centres or particles), structure of arrays, so that the loops inside a model
// vectorise across points. Stresses are Cauchy, tensile positive, in Pa; tensor
// components in the order xx, yy, zz, xy, yz, xz (tensor shear, not engineering).
#pragma once

#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace anvil {

// One batch of points. The caller owns every array; each holds `n` values.
struct MaterialBatch {
  int n = 0;
  double dt = 0;               // time increment, s
  const double* d[6] = {};     // rate of deformation at the mid-step, 1/s
  const double* density = {};  // current density, kg/m^3
  double* stress[6] = {};      // in: old stress already rotated to the new frame; out: new
  double* plastic_strain = {}; // equivalent plastic strain (models with plasticity)
  double* temperature = {};    // K (models with thermal softening)
  double* wave_speed = {};     // out: longitudinal wave speed, m/s
  // Specific internal energy at the new state, J/kg (equations of state read it; null
  // where the caller does not track it, e.g. the hexahedra: models that need it are
  // rejected there at setup).
  const double* energy = {};
};

// A deck parameter of a model: name, unit, and the admissible range that the deck reader
// enforces with file, line and key in the message.
struct ParamSpec {
  std::string_view name;
  std::string_view unit;
  bool required = true;
  double default_value = 0;
  double min = -1e300, max = 1e300;
  bool min_exclusive = false, max_exclusive = false;
  std::string_view doc;
};
using ParamValues = std::map<std::string, double, std::less<>>;

// A tabulated parameter of a model (a hardening curve): points (x[i], y[i]), x strictly
// increasing. The spec names it and its two units; what makes a table admissible beyond
// that (its first x, monotone y) is the model's own check (MaterialModel::check).
struct TableSpec {
  std::string_view name;
  std::string_view x_name, x_unit, y_name, y_unit;
  std::string_view doc;
};
struct ParamTable {
  std::vector<double> x, y;
};
using TableValues = std::map<std::string, ParamTable, std::less<>>;

// What is wrong with a complete set of parameters beyond each one's range (a model's
// cross-parameter rules), and under which key: empty `why` when nothing is.
struct ParamProblem {
  std::string key, why;
  int point = -1; // a table's point at fault (its index), or -1
};

// Isotropic elastic constants shared by every solid model.
struct ElasticConstants {
  double density = 0;        // reference density, kg/m^3
  double youngs_modulus = 0; // Pa
  double poissons_ratio = 0;
  double shear = 0;  // G, Pa
  double bulk = 0;   // K, Pa
  double lambda = 0; // Lame's first parameter, Pa
  static ElasticConstants from(const ParamValues& p);
  // The constants that stand for a fluid's stiffness where a solid's are asked for
  // (penalty stiffness, wave speed, reporting): the bulk modulus K, no shear.
  static ElasticConstants no_shear(double density, double bulk);
  double plane_wave_modulus() const { return lambda + 2 * shear; } // M = K + 4G/3
};

// Empty, or why the elastic parameters p (density, youngs_modulus, poissons_ratio, each
// in its range) give no usable plane wave speed sqrt(M / density): density 1e-300 with E
// 1e300 made a stable step of 0 s (QA round 21). The deck readers refuse them.
std::string elastic_wave_problem(const ParamValues& p);

class Material {
public:
  explicit Material(const ParamValues& p) : elastic_(ElasticConstants::from(p)) {}
  // For models without Young's modulus (fluids): the caller gives the constants that
  // stand for its stiffness (density, bulk modulus; shear zero).
  explicit Material(const ElasticConstants& c) : elastic_(c) {}
  virtual ~Material() = default;

  // Advances the stress of every point in the batch by one step.
  virtual void update(const MaterialBatch& batch) const = 0;
  virtual bool has_plastic_strain() const { return false; }
  // The current flow (yield) stress of each point after update(), Pa, into out[0..n):
  // what the assumed-strain hourglass control limits its bending forces with. Models
  // with plastic strain override it; the others have no yield surface and give +inf.
  virtual void flow_stress(const MaterialBatch& batch, double* out) const;
  virtual bool has_temperature() const { return false; }
  virtual double initial_temperature() const { return 0; }
  // True when update() reads MaterialBatch::energy (equations of state, gases).
  virtual bool needs_energy() const { return false; }
  // Specific internal energy (J/kg) and pressure (Pa) of the undisturbed material.
  virtual double initial_energy() const { return 0; }
  virtual double initial_pressure() const { return 0; }

  const ElasticConstants& elastic() const { return elastic_; }

private:
  ElasticConstants elastic_;
};

// The registry: deck name = class = file (`j2_plasticity` -> J2Plasticity ->
// j2_plasticity.cpp).
struct MaterialModel {
  std::string_view name;
  std::span<const ParamSpec> params;
  std::span<const TableSpec> tables; // tabulated parameters (all optional)
  std::unique_ptr<Material> (*make)(const ParamValues&, const TableValues&);
  std::string_view doc;
  // The model's rules across its parameters, after every parameter has passed its range
  // and the defaults are filled in (null: none). Both deck readers call it.
  ParamProblem (*check)(const ParamValues&, const TableValues&) = nullptr;
};
std::span<const MaterialModel> material_models();
const MaterialModel* find_material_model(std::string_view name);

// An equation of state p(rho, e) that replaces the pressure of a strength model (the
// strength model keeps the deviator): `eos: {model: mie_gruneisen, ...}` under a
// material. Same registry pattern: deck name = class = file.
class Eos {
public:
  virtual ~Eos() = default;
  // Pressure (Pa, compression positive) and the squared bulk sound speed dp/drho
  // (m^2/s^2) at density rho (kg/m^3) and specific internal energy e (J/kg), reference
  // density rho0; n points, arrays owned by the caller.
  virtual void pressure(int n, double rho0, const double* rho, const double* e, double* p,
                        double* c2) const = 0;
};
struct EosModel {
  std::string_view name;
  std::span<const ParamSpec> params;
  std::unique_ptr<Eos> (*make)(const ParamValues&);
  std::string_view doc;
};
std::span<const EosModel> eos_models();
const EosModel* find_eos_model(std::string_view name);

// A material as the deck defines it: the strength model `model` with `params`, and, when
// eos_model is not empty, its pressure replaced by that equation of state.
std::unique_ptr<Material> make_material(std::string_view model, const ParamValues& params,
                                        const TableValues& tables, std::string_view eos_model,
                                        const ParamValues& eos_params);

// The equivalent (von Mises) strain rate sqrt(2/3 D':D') of point p of a batch, D' the
// deviator of the rate of deformation: the rate of a uniaxial test, which the rate laws'
// constants (Johnson-Cook's C, Cowper-Symonds' C and p) are fitted to.
double equivalent_strain_rate(const MaterialBatch& b, int p);

} // namespace anvil
