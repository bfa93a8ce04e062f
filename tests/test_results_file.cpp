// The results file written by `mpmvv run` holds what reports/results-format.md
// documents, for a completed run and for a run the solver stopped; and the
// HDF5 writer under it gives the bytes HDF5 itself would.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "solver/io/hdf5.hpp"
#include "tools/app/scene/scene.hpp"

namespace {

namespace fs = std::filesystem;

int run_mpmvv(const std::string& args) {
  const std::string command = std::string(MPMVV_BINARY) + " run " + MPMVV_SOURCE_DIR +
                              "/suites/scenes/ring.toml -q " + args + " > /dev/null 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "mpmvv-results-test";
  fs::create_directories(dir);
  const fs::path p = dir / name;
  fs::remove(p);
  return p;
}

std::vector<hsize_t> dims_of(const mpmvv::h5::Group& g, const std::string& name) {
  std::vector<hsize_t> dims;
  g.read_doubles(name, &dims);
  return dims;
}

}  // namespace

// A completed run stores status, timings, every scene key, particles, probes and errors.
TEST(ResultsFile, CompletedRunHoldsTheDocumentedLayout) {
  const fs::path out = scratch("completed.h5");
  ASSERT_EQ(run_mpmvv("--set cells=32 --set end_time=0.25 --set output_times=0.1 -o " + out.string()), 0);
  ASSERT_TRUE(fs::exists(out));
  EXPECT_FALSE(fs::exists(out.string() + ".partial"));
  const mpmvv::h5::File file = mpmvv::h5::File::open_read(out.string());
  const mpmvv::h5::Group root = file.root();

  EXPECT_EQ(root.attribute_string("status"), "completed");
  EXPECT_EQ(root.attribute_string("failure_reason"), "");
  EXPECT_GT(root.attribute_int("steps"), 0);
  EXPECT_GT(root.attribute_double("wall_time_s"), 0.0);
  EXPECT_GT(root.attribute_double("forcing_time_s"), 0.0);
  EXPECT_DOUBLE_EQ(root.attribute_double("h"), 3.0 / 32.0);
  EXPECT_GT(root.attribute_double("dt"), 0.0);
  EXPECT_EQ(root.attribute_string("method"), "cpdi");
  EXPECT_EQ(root.attribute_int("particles_per_direction"), 2);
  EXPECT_EQ(root.attribute_int("cells"), 32);
  EXPECT_NE(root.attribute_string("configuration").find("cells = 32"), std::string::npos);
  EXPECT_NE(root.attribute_string("scene_file_text").find("scene = \"ring\""), std::string::npos);
  EXPECT_EQ(root.attribute_string("overrides"), "cells=32\nend_time=0.25\noutput_times=0.1");
  EXPECT_NE(root.attribute_string("version").find("mpmvv"), std::string::npos);
  // Every scene key is an attribute of its own.
  for (const mpmvv::app::KeySpec& key : mpmvv::app::find_scene_type("ring")->keys())
    EXPECT_GE(H5Aexists(root.id(), key.name.c_str()), 1) << key.name;

  const std::int64_t n = root.attribute_int("particle_count");
  const mpmvv::h5::Group particles = root.open_group("particles");
  EXPECT_EQ(dims_of(particles, "reference_position"), (std::vector<hsize_t>{hsize_t(n), 2}));
  EXPECT_EQ(dims_of(particles, "position"), (std::vector<hsize_t>{hsize_t(n), 2}));
  EXPECT_EQ(dims_of(particles, "volume"), (std::vector<hsize_t>{hsize_t(n)}));

  const mpmvv::h5::Group probes = root.open_group("probes");
  for (const char* line : {"theta0", "theta_plus45", "theta_minus45"}) {
    const mpmvv::h5::Group g = probes.open_group(line);
    EXPECT_EQ(dims_of(g, "reference_radius"), (std::vector<hsize_t>{51})) << line;
    EXPECT_EQ(dims_of(g, "angular_displacement"), (std::vector<hsize_t>{2, 51})) << line;
    EXPECT_EQ(dims_of(g, "exact_angular_displacement"), (std::vector<hsize_t>{2, 51})) << line;
  }
  const mpmvv::h5::Group point = probes.open_group("point_R1");
  EXPECT_EQ(dims_of(point, "time"), (std::vector<hsize_t>{hsize_t(root.attribute_int("steps"))}));

  // The energy balance's scale at each output time: the larger of the initial
  // energy and the largest abs(work) any one agent has done by the output
  // times so far (the ring: the body force's work).
  const mpmvv::h5::Group monitors = probes.open_group("monitors");
  const std::vector<double> scale = monitors.read_doubles("energy_scale");
  ASSERT_EQ(scale.size(), 2u);
  double largest = monitors.attribute_double("initial_energy");
  for (std::size_t k = 0; k < 2; ++k) {
    for (const char* work : {"work_body_force", "work_constraints", "work_contact", "work_damping"})
      largest = std::max(largest, std::abs(monitors.read_doubles(work)[k]));
    EXPECT_EQ(scale[k], largest) << k;
  }
  EXPECT_GT(scale[1], monitors.attribute_double("initial_energy"));  // the force's work counts

  const mpmvv::h5::Group errors = root.open_group("errors");
  EXPECT_EQ(errors.read_doubles("time"), (std::vector<double>{0.1, 0.25}));
  for (const char* name : {"L1_theta0", "L1_theta_plus45", "L1_theta_minus45", "particle_L1", "particle_L2",
                           "particle_Linf"}) {
    const std::vector<double> values = errors.read_doubles(name);
    ASSERT_EQ(values.size(), 2u) << name;
    EXPECT_GT(values[1], 0.0) << name;
  }
}

// Corner domains are stored with the particles, and only for a run that has
// them, counter-clockwise and in the particles' order: each quadrilateral's
// area is its particle's volume (det F_p follows the mean velocity gradient
// over the quadrilateral, whose trace is the rate of its area; 1e-13 measured
// here, where the twisted ring's domains reach a distortion of 2.1 and none
// splits).
TEST(ResultsFile, CornerDomainsAreStoredAndTileTheBody) {
  const fs::path out = scratch("corners.h5"), plain = scratch("plain.h5");
  ASSERT_EQ(run_mpmvv("--set cells=32 --set end_time=1 --set output_times=1 --set cpdi_domain=corners -o " +
                      out.string()),
            0);
  ASSERT_EQ(run_mpmvv("--set cells=32 --set end_time=0.01 --set output_times=0.01 -o " + plain.string()), 0);
  const mpmvv::h5::File file = mpmvv::h5::File::open_read(out.string());
  const mpmvv::h5::Group particles = file.root().open_group("particles");
  const std::size_t n = std::size_t(file.root().attribute_int("particle_count"));
  std::vector<hsize_t> dims;
  const std::vector<double> c = particles.read_doubles("domain_corners", &dims);
  ASSERT_EQ(dims, (std::vector<hsize_t>{hsize_t(n), 4, 2}));
  const std::vector<double> volume = particles.read_doubles("volume");
  const std::vector<double> x = particles.read_doubles("position");
  double area = 0.0, total_volume = 0.0, worst = 0.0;
  for (std::size_t p = 0; p < n; ++p) {
    double twice = 0.0;
    double mean[2] = {0.0, 0.0};
    for (int k = 0; k < 4; ++k) {
      const double* a = &c[8 * p + 2 * std::size_t(k)];
      const double* b = &c[8 * p + 2 * std::size_t((k + 1) % 4)];
      twice += a[0] * b[1] - b[0] * a[1];
      mean[0] += 0.25 * a[0];
      mean[1] += 0.25 * a[1];
    }
    area += 0.5 * twice;
    total_volume += volume[p];
    worst = std::max(worst, std::abs(0.5 * twice / volume[p] - 1.0));
    EXPECT_LT(std::hypot(mean[0] - x[2 * p], mean[1] - x[2 * p + 1]), 0.01) << p;  // the particle sits in its domain
  }
  EXPECT_NEAR(area / total_volume, 1.0, 1e-9);
  EXPECT_LT(worst, 1e-9);
  const mpmvv::h5::File plain_file = mpmvv::h5::File::open_read(plain.string());
  EXPECT_EQ(H5Lexists(plain_file.root().open_group("particles").id(), "domain_corners", H5P_DEFAULT), 0);
}

// A run the solver stops is exit status 1 with its reason, time, step and
// particle recorded, and the rows of every output time it reached kept.
TEST(ResultsFile, FailedRunRecordsWhyWhenAndWhere) {
  const fs::path out = scratch("failed.h5");
  // Linear MPM at A = 3 on 32 cells: measured to stop with NaN between t = 0.1 and 1.
  ASSERT_EQ(run_mpmvv("--set cells=32 --set amplitude=3 --set method=linear -o " + out.string()), 1);
  const mpmvv::h5::File file = mpmvv::h5::File::open_read(out.string());
  const mpmvv::h5::Group root = file.root();
  EXPECT_EQ(root.attribute_string("status"), "failed");
  EXPECT_FALSE(root.attribute_string("failure_reason").empty());
  EXPECT_FALSE(root.attribute_string("failure_detail").empty());
  const double failure_time = root.attribute_double("failure_time");
  EXPECT_GT(failure_time, 0.0);
  EXPECT_LT(failure_time, 1.0);
  EXPECT_DOUBLE_EQ(root.attribute_double("time_reached"), failure_time);
  EXPECT_EQ(root.attribute_int("failure_step"), root.attribute_int("steps"));
  EXPECT_GE(root.attribute_int("failure_particle"), 0);
  EXPECT_LT(root.attribute_int("failure_particle"), root.attribute_int("particle_count"));
  std::vector<double> reached;
  for (double t : root.attribute_doubles("output_times"))
    if (t < failure_time) reached.push_back(t);
  ASSERT_FALSE(reached.empty());
  EXPECT_EQ(root.open_group("errors").read_doubles("time"), reached);
}

// A run stopped by SIGTERM before its end time writes what it computed, marked
// "interrupted", and exits 130: the errors at the output times it reached,
// nothing after them. `timeout` sends the signal after 5 s to a run that
// needs about 20 s (the ring on 256 cells to t = 1 s, one thread).
TEST(ResultsFile, RunStoppedBySignalWritesWhatItHasAsInterrupted) {
  const fs::path out = scratch("interrupted.h5");
  const fs::path log = scratch("interrupted.log");
  // The signal comes a second after the run has printed its configuration,
  // the moment it starts to step (run_case.cpp), however long the set-up
  // took on a loaded machine; the shell's status is the run's.
  const std::string command = "sh -c '" + std::string(MPMVV_BINARY) + " run " + MPMVV_SOURCE_DIR +
                              "/suites/scenes/ring.toml -t 1 --set cells=256 --set end_time=1 " +
                              "--set output_times=[0.01,0.02,0.9] -o " + out.string() + " > /dev/null 2> " +
                              log.string() + " & run=$!; until grep -q configuration: " + log.string() +
                              " || ! kill -0 $run 2> /dev/null; do sleep 0.1; done; sleep 1; kill -TERM $run; " +
                              "wait $run'";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130);
  ASSERT_TRUE(fs::exists(out));
  EXPECT_FALSE(fs::exists(out.string() + ".partial"));
  const mpmvv::h5::File file = mpmvv::h5::File::open_read(out.string());
  const mpmvv::h5::Group root = file.root();
  EXPECT_EQ(root.attribute_string("status"), "interrupted");
  EXPECT_EQ(root.attribute_string("failure_reason"), "interrupted");
  EXPECT_GT(root.attribute_int("steps"), 0);
  const double reached = root.attribute_double("time_reached");
  EXPECT_GT(reached, 0.0);
  EXPECT_LT(reached, 0.9);
  EXPECT_DOUBLE_EQ(root.attribute_double("failure_time"), reached);
  std::vector<hsize_t> dims;
  const std::vector<double> times = root.open_group("errors").read_doubles("time", &dims);
  for (double t : times) EXPECT_LE(t, reached);
}

// A case that cannot fit in the machine's memory is refused before anything
// is allocated, with one line naming the keys (exit 2, no results file); a
// thread count beyond 1024 is refused by the command line.
TEST(ResultsFile, ACaseThatCannotFitIsRefusedBeforeItStarts) {
  const fs::path out = scratch("too-big.h5"), message = scratch("too-big.txt");
  const std::string command = std::string(MPMVV_BINARY) + " run " + MPMVV_SOURCE_DIR +
                              "/suites/scenes/ring.toml -q -t 1 --set cells=20000 -o " + out.string() + " > " +
                              message.string() + " 2>&1";
  const int status = std::system(command.c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2);
  std::ifstream in(message);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("cells = 20000, particles_per_direction = 2 and threads = 1 need about"), std::string::npos)
      << text;
  EXPECT_NE(text.find("use fewer cells, particles per direction or threads"), std::string::npos) << text;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(run_mpmvv("-t 100000 --set cells=32 --set end_time=0.01 -o " + scratch("threads.h5").string()), 2);
}

namespace {

std::string bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The same content for every file the tests below compare: attributes, a
// dataset written whole and a particle-sized one written by rows.
constexpr std::size_t kRows = 3 * (std::size_t(1) << 16) + 17;  // crosses write_rows' blocks

double row_value(std::size_t row, std::size_t k) { return 0.5 * double(row) - 3.0 * double(k) + 1e-3; }

void fill_content(mpmvv::h5::Group& root, bool by_rows) {
  root.set_attribute("status", "completed");
  root.set_attribute("steps", std::int64_t(123));
  root.write("time", std::vector<double>{0.1, 0.2, 0.3}, {3});
  mpmvv::h5::Group g = root.create_group("particles");
  if (by_rows) {
    g.write_rows("position", {kRows, 2}, [](std::size_t first, std::size_t count, double* out) {
      for (std::size_t r = first; r < first + count; ++r)
        for (std::size_t k = 0; k < 2; ++k) *out++ = row_value(r, k);
    });
  } else {
    std::vector<double> whole(2 * kRows);
    for (std::size_t r = 0; r < kRows; ++r)
      for (std::size_t k = 0; k < 2; ++k) whole[2 * r + k] = row_value(r, k);
    g.write("position", whole, {kRows, 2});
  }
}

// fill_content written to `p` by save().
void save_content(const fs::path& p, bool by_rows) {
  mpmvv::h5::File file = mpmvv::h5::File::create(p.string());
  {
    mpmvv::h5::Group root = file.root();
    fill_content(root, by_rows);
  }
  file.save();
}

}  // namespace

// save() writes the buffer HDF5 hands over as the file closes; it must be the
// file H5Fget_file_image copies out of the same in-memory file (the way the
// image was taken before, at twice the memory).
TEST(Hdf5File, SavedFileIsTheImageHdf5CopiesOut) {
  const fs::path saved = scratch("handed-over.h5");
  save_content(saved, false);
  // The same file, built with the same properties but no callbacks, copied out.
  std::string copied;
  {
    const hid_t fcpl = H5Pcreate(H5P_FILE_CREATE);
    ASSERT_GE(H5Pset_link_creation_order(fcpl, H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED), 0);
    const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    ASSERT_GE(H5Pset_fapl_core(fapl, std::size_t(1) << 20, 0), 0);
    ASSERT_GE(H5Pset_fclose_degree(fapl, H5F_CLOSE_STRONG), 0);
    const hid_t id = H5Fcreate(scratch("copied.h5").c_str(), H5F_ACC_TRUNC, fcpl, fapl);
    ASSERT_GE(id, 0);
    {
      mpmvv::h5::Group root(mpmvv::h5::Handle(H5Gopen2(id, "/", H5P_DEFAULT), H5Gclose), "/");
      fill_content(root, false);
    }
    ASSERT_GE(H5Fflush(id, H5F_SCOPE_GLOBAL), 0);
    const ssize_t size = H5Fget_file_image(id, nullptr, 0);
    ASSERT_GT(size, 0);
    copied.resize(std::size_t(size));
    ASSERT_EQ(H5Fget_file_image(id, copied.data(), copied.size()), size);
    ASSERT_GE(H5Fclose(id), 0);
    ASSERT_GE(H5Pclose(fapl), 0);
    ASSERT_GE(H5Pclose(fcpl), 0);
  }
  const std::string written = bytes_of(saved);
  ASSERT_EQ(written.size(), copied.size());
  EXPECT_TRUE(written == copied) << "the saved file differs from HDF5's image of it";
}

// A dataset written a block of rows at a time is the file a whole write gives.
TEST(Hdf5File, RowsWrittenInBlocksGiveTheBytesOfAWholeWrite) {
  std::string files[2];
  const fs::path by_rows_path = scratch("by-rows.h5");
  for (const bool by_rows : {false, true}) {
    const fs::path p = by_rows ? by_rows_path : scratch("whole.h5");
    save_content(p, by_rows);
    files[by_rows] = bytes_of(p);
  }
  ASSERT_GT(files[0].size(), 2 * kRows * sizeof(double));
  EXPECT_TRUE(files[0] == files[1]);
  const mpmvv::h5::File file = mpmvv::h5::File::open_read(by_rows_path.string());
  std::vector<hsize_t> dims;
  const std::vector<double> read = file.root().open_group("particles").read_doubles("position", &dims);
  ASSERT_EQ(dims, (std::vector<hsize_t>{kRows, 2}));
  EXPECT_EQ(read[2 * (kRows - 1) + 1], row_value(kRows - 1, 1));
}

// Two writes of the same content give the same bytes only if no object header
// holds the clock: HDF5 stamps the root group, groups and datasets unless told
// not to, and two writes either side of a second's tick then differ.
TEST(Hdf5File, ObjectsCarryNoTimeStamps) {
  const fs::path p = scratch("untimed.h5");
  save_content(p, false);
  const hid_t file = H5Fopen(p.string().c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  for (const char* object : {"/", "/particles", "/particles/position", "/time"}) {
    H5O_info_t info;
    ASSERT_GE(H5Oget_info_by_name(file, object, &info, H5P_DEFAULT), 0) << object;
    EXPECT_EQ(info.ctime, 0) << object;
    EXPECT_EQ(info.mtime, 0) << object;
  }
  H5Fclose(file);
}

// Saving while a group is open would leave HDF5 holding the file open; it is
// refused with the reason, and nothing is written.
TEST(Hdf5File, SavingWithAGroupOpenIsRefused) {
  const fs::path p = scratch("open-group.h5");
  mpmvv::h5::File file = mpmvv::h5::File::create(p.string());
  mpmvv::h5::Group root = file.root();
  root.set_attribute("status", "completed");
  try {
    file.save();
    FAIL() << "saved with a group open";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("still open"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(p));
}
