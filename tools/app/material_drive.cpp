#include "material_drive.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <ostream>
#include <sstream>

#include <fmt/format.h>

#include "toml_file.hpp"
#include <fmt/ranges.h>

#include "analytic/f_tables.hpp"
#include "analytic/principal_stress.hpp"
#include "json.hpp"
#include "mms/jet.hpp"
#include "scene/setup.hpp"
#include "solver/model.hpp"

namespace mpmvv::app {
namespace {

using analytic::Deformation;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A path of homogeneous states, s from 0 to 1.
struct Path {
  std::string name;
  std::vector<double> s;
  std::vector<Deformation> F;
};

// The path sampled at `steps` equal intervals of s and at the corners of a
// piecewise path (a table file's rows), so that no interval of the work's
// quadrature straddles a corner.
template <class At>
Path sampled(const std::string& name, const At& at, int steps, std::vector<double> corners = {}) {
  Path p{name, {}, {}};
  for (int k = 0; k <= steps; ++k) corners.push_back(double(k) / steps);
  std::sort(corners.begin(), corners.end());
  for (double s : corners)
    if (p.s.empty() || s > p.s.back() + 1e-12) {
      p.s.push_back(s);
      p.F.push_back(at(s));
      const double J = p.F.back().F.determinant() * p.F.back().F33;
      if (!(J > 0.0))
        throw ConfigError(fmt::format("F-table {}: J = {:.6g} at s = {:.6g} (F is linear in s between rows)", name, J,
                                      s));
    }
  return p;
}

// A table file: one state a row, "s F11 F12 F21 F22 [F33]" (commas or blanks
// between the numbers; '#' starts a comment); s increasing, J > 0. F is
// linear in s between rows.
Path table_file(const std::string& file, int steps) {
  std::istringstream in(read_regular_file(file, "F-table file"));
  Path p{std::filesystem::path(file).filename().string(), {}, {}};
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    line = line.substr(0, line.find('#'));
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream row(line);
    std::vector<double> v;
    std::string word;
    while (row >> word) {
      std::size_t used = 0;
      double x = kNaN;
      try {
        x = std::stod(word, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != word.size() || !std::isfinite(x))
        throw ConfigError(fmt::format("{}:{}: '{}' is not a finite number", file, number, word));
      v.push_back(x);
    }
    if (v.empty()) continue;
    if (v.size() != 5 && v.size() != 6)
      throw ConfigError(fmt::format("{}:{}: {} numbers; a row is s F11 F12 F21 F22 [F33]", file, number, v.size()));
    Deformation d;
    d.F << v[1], v[2], v[3], v[4];
    d.F33 = v.size() == 6 ? v[5] : 1.0;
    const double J = d.F.determinant() * d.F33;
    if (!(J > 0.0)) throw ConfigError(fmt::format("{}:{}: J = det F = {:.6g} is not positive", file, number, J));
    if (!p.s.empty() && !(v[0] > p.s.back()))
      throw ConfigError(fmt::format("{}:{}: s = {:.6g} does not increase (previous row {:.6g})", file, number, v[0],
                                    p.s.back()));
    p.s.push_back(v[0]);
    p.F.push_back(d);
  }
  if (p.s.size() < 2) throw ConfigError(fmt::format("{}: an F-table needs at least two rows", file));
  const double s0 = p.s.front(), span = p.s.back() - s0;
  for (double& s : p.s) s = (s - s0) / span;  // the rotation grows with the path's fraction
  const auto at = [&p](double s) {
    const std::size_t k = std::min<std::size_t>(
        std::size_t(std::upper_bound(p.s.begin(), p.s.end(), s) - p.s.begin()), p.s.size() - 1);
    const double w = (s - p.s[k - 1]) / (p.s[k] - p.s[k - 1]);
    return Deformation{(1.0 - w) * p.F[k - 1].F + w * p.F[k].F, (1.0 - w) * p.F[k - 1].F33 + w * p.F[k].F33};
  };
  return sampled(p.name, at, steps, p.s);
}

Path path_named(const std::string& name, int steps) {
  for (const analytic::FTable& t : analytic::standard_f_tables())
    if (t.name == name) return sampled(t.name, t.at, steps);
  if (std::filesystem::exists(name)) return table_file(name, steps);
  std::string names;
  for (const analytic::FTable& t : analytic::standard_f_tables()) names += (names.empty() ? "" : ", ") + t.name;
  throw ConfigError(fmt::format("--table '{}': neither a standard F-table ({}) nor a file", name, names));
}

Path rotated(const Path& p, double angle) {
  Path r = p;
  for (std::size_t k = 0; k < p.F.size(); ++k) r.F[k].F = analytic::rotation(angle * p.s[k]) * p.F[k].F;
  return r;
}

// The material's keys as a scene declares them, density aside (a material
// point has no mass), with a Mooney-Rivlin whose C2 is not zero so that both
// of its terms are driven (2 (C1 + C2) = mu as for the scenes' default).
Config material_config(const std::vector<std::string>& overrides) {
  std::vector<KeySpec> keys;
  for (KeySpec k : material_keys("neo-hookean", 577.0, 385.0, 1000.0)) {
    if (k.name == "density") continue;
    if (k.name == "c1") k.default_value = 0.3 * 385.0;
    if (k.name == "c2") k.default_value = 0.2 * 385.0;
    keys.push_back(k);
  }
  Config c("material drive", keys);
  for (const std::string& o : overrides) c.set_from_text(o);
  return c;
}

struct Row {
  std::string material, table;
  double rotation_degrees = 0.0;
  double stress_error = kNaN;       // against the principal-stretch form
  double energy_error = kNaN;
  double derivative_error = kNaN;   // P (or the small-strain stress) against dW/dF
  double work_error = kNaN;         // int P : dF along the path against W(end) - W(0)
  double objectivity_error = kNaN;  // sigma(R F) against R sigma(F) R^T
  bool objective = true;            // whether the material claims objectivity
  std::string verdict;
};

double largest(const Eigen::Matrix2d& a, double b) { return std::max(a.cwiseAbs().maxCoeff(), std::abs(b)); }

// dW/dF (in-plane block and the F_33 component) by forward differentiation
// of the material's own energy.
template <class Material>
std::pair<Eigen::Matrix2d, double> energy_derivative(const Material& m, const Deformation& d) {
  using J5 = mms::Jet<double, 5>;
  Eigen::Matrix<J5, 2, 2> F;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) F(i, j) = J5::variable(d.F(i, j), 2 * i + j);
  const J5 W = m.energy_density(F, J5::variable(d.F33, 4));
  Eigen::Matrix2d dW;
  dW << W.d[0], W.d[1], W.d[2], W.d[3];
  return {dW, W.d[4]};
}

// The stress the energy is differentiated into: the first Piola stress
// J sigma F^-T of a finite-strain solid (its F_33 component J sigma_33 / F_33),
// the stress itself of the small-strain solid (dW/d grad u = sigma).
template <class Material>
std::pair<Eigen::Matrix2d, double> conjugate_stress(const Deformation& d, const Stress<double>& s) {
  if constexpr (!Material::finite_strain) return {s.in_plane, s.out_of_plane};
  const double J = d.F.determinant() * d.F33;
  return {J * s.in_plane * d.F.inverse().transpose(), J * s.out_of_plane / d.F33};
}

std::optional<analytic::NeoHookeanStretches> stretches_of(const NeoHookean& m) { return {{m.lambda, m.mu}}; }
std::optional<analytic::MooneyRivlinStretches> stretches_of(const MooneyRivlin& m) {
  return {{m.c1, m.c2, m.bulk_modulus}};
}
std::optional<analytic::NeoHookeanStretches> stretches_of(const LinearElastic&) { return std::nullopt; }

template <class Material>
Row drive(const Material& m, const std::string& material, const Path& path, const Path& unrotated, double degrees) {
  Row row{material, path.name, degrees};
  row.objective = Material::finite_strain;
  const auto exact = stretches_of(m);
  const double modulus = m.small_strain_moduli().mu;  // the scale of a path without stress
  double stress_scale = modulus, energy_scale = modulus, derivative_scale = modulus;
  double stress_error = 0.0, energy_error = 0.0, derivative_error = 0.0, objectivity_error = 0.0, work = 0.0;
  std::vector<std::pair<Eigen::Matrix2d, double>> conjugate;
  for (std::size_t k = 0; k < path.F.size(); ++k) {
    const Deformation& d = path.F[k];
    const Stress<double> s = m.stress(d.F, d.F33);
    stress_scale = std::max(stress_scale, largest(s.in_plane, s.out_of_plane));
    const double W = m.energy_density(d.F, d.F33);
    energy_scale = std::max(energy_scale, std::abs(W));
    if (exact) {
      const analytic::ExactStress e = analytic::principal_stress(*exact, d);
      stress_error = std::max(stress_error, largest(s.in_plane - e.in_plane, s.out_of_plane - e.out_of_plane));
      energy_error = std::max(energy_error, std::abs(W - analytic::principal_energy(*exact, d)));
    }
    const auto [dW, dW33] = energy_derivative(m, d);
    conjugate.push_back(conjugate_stress<Material>(d, s));
    derivative_scale = std::max(derivative_scale, largest(conjugate.back().first, conjugate.back().second));
    derivative_error = std::max(derivative_error, largest(conjugate.back().first - dW, conjugate.back().second - dW33));
    if (&path != &unrotated) {
      const Deformation& u = unrotated.F[k];
      const Stress<double> su = m.stress(u.F, u.F33);
      const Eigen::Matrix2d R = d.F * u.F.inverse();
      objectivity_error = std::max(objectivity_error, largest(s.in_plane - R * su.in_plane * R.transpose(),
                                                              s.out_of_plane - su.out_of_plane));
    }
  }
  // The stress power along the straight segments between samples, by
  // Simpson's rule (fourth order in the samples' spacing): a stress that is
  // the energy's derivative does the work the energy stores, whatever the path.
  for (std::size_t k = 0; k + 1 < path.F.size(); ++k) {
    const Deformation &a = path.F[k], &b = path.F[k + 1];
    const Deformation mid{0.5 * (a.F + b.F), 0.5 * (a.F33 + b.F33)};
    const auto cm = conjugate_stress<Material>(mid, m.stress(mid.F, mid.F33));
    const Eigen::Matrix2d P = (conjugate[k].first + 4.0 * cm.first + conjugate[k + 1].first) / 6.0;
    const double P33 = (conjugate[k].second + 4.0 * cm.second + conjugate[k + 1].second) / 6.0;
    work += (P.cwiseProduct(b.F - a.F)).sum() + P33 * (b.F33 - a.F33);
  }
  const Deformation &first = path.F.front(), &last = path.F.back();
  const double stored = m.energy_density(last.F, last.F33) - m.energy_density(first.F, first.F33);
  if (exact) {
    row.stress_error = stress_error / stress_scale;
    row.energy_error = energy_error / energy_scale;
  }
  row.derivative_error = derivative_error / derivative_scale;
  row.work_error = std::abs(work - stored) / energy_scale;
  if (&path != &unrotated) row.objectivity_error = objectivity_error / stress_scale;
  return row;
}

void judge(Row& row, double tolerance) {
  std::vector<std::string> failed;
  auto check = [&](const char* what, double error) {
    if (!(std::isnan(error) || error <= tolerance)) failed.push_back(fmt::format("{} {:.2e}", what, error));
  };
  check("stress", row.stress_error);
  check("energy", row.energy_error);
  check("dW/dF", row.derivative_error);
  check("work", row.work_error);
  if (row.objective) check("objectivity", row.objectivity_error);
  if (!failed.empty()) {
    row.verdict = "FAIL:";
    for (const std::string& f : failed) row.verdict += " " + f;
  } else if (!row.objective && !std::isnan(row.objectivity_error)) {
    row.verdict = "pass; not objective (small strain)";
  } else {
    row.verdict = "PASS";
  }
}

std::string cell(double x) { return std::isnan(x) ? "-" : fmt::format("{:.1e}", x); }

Json row_json(const Row& r) {
  auto number = [](double x) { return std::isnan(x) ? Json(nullptr) : Json(x); };
  return {{"material", r.material},
          {"table", r.table},
          {"rotation_degrees", r.rotation_degrees},
          {"stress_error", number(r.stress_error)},
          {"energy_error", number(r.energy_error)},
          {"derivative_error", number(r.derivative_error)},
          {"work_error", number(r.work_error)},
          {"objectivity_error", number(r.objectivity_error)},
          {"objective", r.objective},
          {"verdict", r.verdict}};
}

}  // namespace

std::string material_tables() {
  std::string out = "The standard F-tables (s from 0 to 1; mpmvv material drive --table NAME):\n";
  for (const analytic::FTable& t : analytic::standard_f_tables())
    out += fmt::format("  {:22} {}\n", t.name, t.description);
  out += "A table file holds rows 's F11 F12 F21 F22 [F33]' (F33 = 1 when absent), s increasing.\n";
  return out;
}

int material_drive(const MaterialDriveRequest& request, std::ostream& out, std::ostream& err) {
  std::vector<Row> rows;
  Config config("material drive", {});
  std::vector<Path> paths;
  try {
    if (!(request.steps >= 2)) throw ConfigError(fmt::format("--steps {}: at least 2", request.steps));
    if (!std::isfinite(request.rotation_degrees))
      throw ConfigError("--rotation: not a finite angle");
    config = material_config(request.overrides);
    // The materials the `material` key declares (scene/setup.cpp: material_keys).
    const std::vector<std::string>& known =
        std::find_if(config.specs().begin(), config.specs().end(), [](const KeySpec& k) {
          return k.name == "material";
        })->choices;
    const std::vector<std::string> materials = request.materials.empty() ? known : request.materials;
    for (const std::string& m : materials)
      if (std::find(known.begin(), known.end(), m) == known.end())
        throw ConfigError(fmt::format("--material '{}': unknown (known: {})", m, fmt::join(known, ", ")));
    std::vector<std::string> tables = request.tables;
    if (tables.empty())
      for (const analytic::FTable& t : analytic::standard_f_tables()) tables.push_back(t.name);
    for (const std::string& t : tables) paths.push_back(path_named(t, request.steps));
    const double angle = request.rotation_degrees * M_PI / 180.0;
    for (const std::string& m : materials) {
      config.set("material", m, Origin{"--material"});
      const MaterialModel model = material_from(config);
      for (const Path& p : paths) {
        std::visit([&](const auto& solid) { rows.push_back(drive(solid, m, p, p, 0.0)); }, model);
        if (angle == 0.0) continue;
        const Path r = rotated(p, angle);
        std::visit([&](const auto& solid) { rows.push_back(drive(solid, m, r, p, request.rotation_degrees)); }, model);
      }
    }
  } catch (const ConfigError& e) {
    err << "mpmvv material drive: " << e.what() << "\n";
    return 2;
  }
  bool ok = true;
  for (Row& r : rows) {
    judge(r, request.tolerance);
    ok = ok && r.verdict.rfind("FAIL", 0) != 0;
  }

  out << fmt::format(
      "Material-point driver: {} F-table(s), each at {} equal intervals of s (and a table file's rows), rotation 0 "
      "and {} deg.\n"
      "Errors are relative to the larger of the path's largest stress (energy) and mu: stress and energy against "
      "the principal-stretch forms, P against dW/dF, the work of P along the path against W(end) - W(0), sigma(R F) "
      "against R sigma(F) R^T. Tolerance {:.0e}.\n\n",
      paths.size(), request.steps, request.rotation_degrees, request.tolerance);
  out << fmt::format("{:15} {:22} {:>8} {:>9} {:>9} {:>9} {:>9} {:>11}  {}\n", "material", "F-table", "rotation",
                     "stress", "energy", "dW/dF", "work", "objectivity", "verdict");
  for (const Row& r : rows)
    out << fmt::format("{:15} {:22} {:>8} {:>9} {:>9} {:>9} {:>9} {:>11}  {}\n", r.material, r.table,
                       fmt::format("{:g}", r.rotation_degrees), cell(r.stress_error), cell(r.energy_error),
                       cell(r.derivative_error), cell(r.work_error), cell(r.objectivity_error), r.verdict);
  out << (ok ? "\nPASS: every check within tolerance\n" : "\nFAIL: some check above tolerance\n");

  if (!request.json.empty()) {
    Json parameters = Json::object();
    for (const KeySpec& k : config.specs())
      if (k.name != "material") parameters[k.name] = std::get<double>(config.value(k.name));
    Json j = {{"command", "mpmvv material drive"},
              {"steps", request.steps},
              {"rotation_degrees", request.rotation_degrees},
              {"tolerance", request.tolerance},
              {"parameters", parameters},
              {"tables", Json::array()},
              {"rows", Json::array()},
              {"passed", ok}};
    for (const Path& p : paths) j["tables"].push_back(p.name);
    for (const Row& r : rows) j["rows"].push_back(row_json(r));
    std::ofstream f(request.json);
    f << json_text(j, 1) << "\n";
    if (!f) {
      err << "mpmvv material drive: cannot write " << request.json << "\n";
      return 2;
    }
  }
  return ok ? 0 : 1;
}

}  // namespace mpmvv::app
