// What the vibrating-bar scenes share (PROBLEMS.md sections 5 and 6): a bar
// in uniaxial strain, a strip two cells high between roller walls, its fixed
// end on the left wall and its free end four cells short of the right one; the
// probe line along its axis and the free end's history, from which the
// period (FFTW locates it, zero crossings measure it) and the amplitude are
// measured against the exact ones.
#pragma once

#include "tools/app/scene/setup.hpp"

namespace mpmvv::app {

// Sets the grid (cells along the bar), the body, the probes, the error
// columns error_period and error_amplitude (|measured / exact - 1|, NaN until
// the history spans a period) and the measurements of `s`.
void set_up_vibrating_strip(SceneSetup& s, double length, int cells, int probe_points, double exact_period,
                            double exact_amplitude);

}  // namespace mpmvv::app
