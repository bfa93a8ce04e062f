// The .xmf sidecar of a results file (XDMF 3, which ParaView's and VisIt's
// readers open): the particles of FILE.h5 as points with their fields, over
// time when the run kept them at every output time (/snapshots), else at the
// end. Written from the results file itself once it is whole, so it names
// only what the file holds; it refers to FILE.h5 by name, so the two move
// together.
#pragma once

#include <string>

namespace mpmvv::app {

// FILE.h5 -> FILE.xmf (FILE.xmf appended to a name without .h5).
std::string xdmf_sidecar_path(const std::string& h5_path);
// The XDMF text for the results file at h5_path; throws h5::Error or
// std::runtime_error.
std::string xdmf_text(const std::string& h5_path);
// Writes it next to the file, through a partial name; throws as xdmf_text or
// on a failed write.
void write_xdmf_sidecar(const std::string& h5_path);

}  // namespace mpmvv::app
