// `mpmvv material`: the material-point driver. Each material of the solver is
// driven through F-tables (analytic/f_tables.hpp, or a table file of F rows)
// with and without a superimposed rotation, and its stress and stored energy
// are compared with
//   - the exact values in principal stretches (analytic/principal_stress.hpp),
//   - the energy's own derivative (P = dW/dF, by automatic differentiation),
//   - the work the stress does along the path (W(end) - W(0)),
//   - the rotated stress of the unrotated path (objectivity),
// every check that applies to the material (the small-strain solid has no
// principal-stretch form and is not objective: its rotated rows say so).
//   tables                          the standard F-tables
//   drive [--material M] [--table T|FILE] [--rotation DEG] [--steps N]
//         [--set k=v] [--tolerance E] [--json FILE]
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace mpmvv::app {

std::string material_tables();

struct MaterialDriveRequest {
  std::vector<std::string> materials;  // empty: every material
  std::vector<std::string> tables;     // names of standard tables or table files; empty: every standard table
  double rotation_degrees = 90.0;      // the superimposed rotation's end angle; 0: unrotated rows only
  int steps = 1000;                    // samples along a standard table's path (the work check is
                                       // fourth order in them: at most 5e-13 at 1000)
  double tolerance = 1e-10;            // largest relative error a check allows
  std::vector<std::string> overrides;  // material keys: lambda=..., c2=...
  std::string json;                    // write the rows here too
};

// Exit status 0 when every check that applies is within the tolerance, 1 when
// one is not, 2 on bad input (one line on err naming what and where).
int material_drive(const MaterialDriveRequest& request, std::ostream& out, std::ostream& err);

}  // namespace mpmvv::app
