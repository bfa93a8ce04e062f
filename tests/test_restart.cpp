// A run saved part way (mpmvv run --pause-at, --checkpoint-every) and
// continued with --resume ends with the bits of a run made in one piece; only
// the same run may go on from a restart file; and the archive under it
// (solver/io/state_archive.hpp) reads back what it wrote.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <hdf5.h>

#include "solver/io/hdf5.hpp"
#include "solver/io/state_archive.hpp"
#include "solver/tensor.hpp"

namespace {

namespace fs = std::filesystem;
using mpmvv::h5::File;
using mpmvv::h5::Group;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "mpmvv-restart-test";
  fs::create_directories(dir);
  const fs::path p = dir / name;
  fs::remove(p);
  fs::remove(p.string() + ".restart");
  return p;
}

// `mpmvv run suites/scenes/<scene> -q <arguments>`: its exit status, and
// what it printed in `messages` when given.
int run(const std::string& scene, const std::string& arguments, std::string* messages = nullptr) {
  // One file per test process: ctest runs the tests of this file at once.
  const fs::path log =
      fs::temp_directory_path() / "mpmvv-restart-test" / ("messages-" + std::to_string(::getpid()) + ".txt");
  const std::string command = std::string(MPMVV_BINARY) + " run " + MPMVV_SOURCE_DIR + "/suites/scenes/" + scene +
                              " -q " + arguments + " > " + log.string() + " 2>&1";
  const int status = std::system(command.c_str());
  if (messages) {
    std::ifstream in(log);
    *messages = std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

// Every dataset under `a` is in `b` with the same bits (NaN equal to NaN);
// the names of those that are not, into `differ`.
void compare_datasets(const Group& a, const Group& b, std::vector<std::string>& differ, std::size_t& count) {
  for (const std::string& name : a.members()) {
    if (a.is_group(name)) {
      compare_datasets(a.open_group(name), b.open_group(name), differ, count);
      continue;
    }
    ++count;
    std::vector<hsize_t> da, db;
    if (!b.has(name) || !same_bits(a.read_doubles(name, &da), b.read_doubles(name, &db)) || da != db)
      differ.push_back(a.path() + "/" + name);
  }
}

// What a run records of its course, to the bit (the wall-clock times aside).
void expect_same_run(const fs::path& one_piece, const fs::path& resumed) {
  const File a = File::open_read(one_piece.string()), b = File::open_read(resumed.string());
  const Group ra = a.root(), rb = b.root();
  std::vector<std::string> differ;
  std::size_t count = 0;
  compare_datasets(ra, rb, differ, count);
  EXPECT_GT(count, 20u);
  EXPECT_TRUE(differ.empty()) << differ.front() << " and " << differ.size() - 1 << " more differ";
  for (const char* name : {"status", "failure_reason", "health", "configuration"})
    EXPECT_EQ(ra.attribute_string(name), rb.attribute_string(name)) << name;
  for (const char* name : {"steps", "particle_steps", "particle_count"})
    EXPECT_EQ(ra.attribute_int(name), rb.attribute_int(name)) << name;
  for (const char* name : {"time_reached", "dt", "dt_min", "dt_max", "frequency_measurements"})
    EXPECT_TRUE(same_bits({ra.attribute_double(name)}, {rb.attribute_double(name)})) << name;
  EXPECT_TRUE(ra.attribute_doubles("resumed_at").empty());
}

struct Case {
  const char* name;
  const char* scene;
  std::string settings;
  double pause_at;
};

}  // namespace

// Paused part way and resumed, each run ends as the same run made in one
// piece: the ring by CPDI with domains split as they grow (the particle count
// changes) on two threads, the stiff vortex's total Lagrangian run under the
// stable time-step rule (the loop's measurements of omega_max), and the
// Hertz cylinder (contact with a moving rigid body, a history after every
// step). The paused run says it was interrupted, keeps its state, and the
// resumed one records where it went on from and removes the state.
TEST(Restart, APausedAndResumedRunEndsWithTheBitsOfARunInOnePiece) {
  const std::vector<Case> cases = {
      {"ring-split", "ring.toml",
       "-t 2 --set cells=32 --set amplitude=1.5 --set split_domains_beyond=1.0 --set end_time=0.2 "
       "--set output_times=[0.1,0.2] --set coverage_samples=2",  // the coverage lattice kept across the pause
       0.18},
      {"stiff-vortex", "stiff-vortex.toml",
       "-t 1 --set method=gimp --set rims=held --set end_time=0.1 --set output_times=[0.05,0.1]", 0.04},
      {"hertz", "hertz-cylinder.toml", "-t 1 --set cells=20", 1e-3},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path whole = scratch(std::string(c.name) + "-whole.h5"), parts = scratch(std::string(c.name) + ".h5");
    const std::string state = parts.string() + ".restart";
    ASSERT_EQ(run(c.scene, c.settings + " -o " + whole.string()), 0);
    EXPECT_FALSE(fs::exists(whole.string() + ".restart")) << "a run not asked to save its state saved it";

    std::string said;
    EXPECT_EQ(run(c.scene, c.settings + " -o " + parts.string() + " --pause-at " + std::to_string(c.pause_at), &said),
              130)
        << said;
    ASSERT_TRUE(fs::exists(state));
    double paused_at = 0.0;
    {
      const File f = File::open_read(parts.string());
      EXPECT_EQ(f.root().attribute_string("status"), "interrupted");
      paused_at = f.root().attribute_double("time_reached");
      EXPECT_GE(paused_at, c.pause_at);
      EXPECT_GT(f.root().attribute_int("steps"), 0);
    }

    EXPECT_EQ(run(c.scene, c.settings + " -o " + parts.string() + " --resume", &said), 0) << said;
    EXPECT_NE(said.find("going on from"), std::string::npos) << said;
    EXPECT_FALSE(fs::exists(state)) << "the state of a run that has ended is kept";
    const File f = File::open_read(parts.string());
    EXPECT_EQ(f.root().attribute_doubles("resumed_at"), std::vector<double>{paused_at});
    expect_same_run(whole, parts);
  }
}

// A restart file holds the state of one run: --resume with a pause already
// reached stops again without saving; --resume refuses it for another
// configuration or thread count, naming what differs (exit 2, nothing run);
// --resume-if-same starts that run from t = 0 and says why; an unreadable
// file is named; and a solver whose state the file cannot hold (the implicit
// static step) refuses to save one.
TEST(Restart, OnlyTheSameRunGoesOnFromARestartFile) {
  const std::string ring = "--set cells=24 --set end_time=0.1 --set output_times=[0.1]";
  const fs::path out = scratch("other.h5");
  const std::string state = out.string() + ".restart";
  ASSERT_EQ(run("ring.toml", "-t 1 " + ring + " -o " + out.string() + " --pause-at 0.03"), 130);
  ASSERT_TRUE(fs::exists(state));

  std::string said;
  // Resumed with --pause-at at or before the saved time: it says it stops at
  // once, and leaves the saved state as it was (no second save of it).
  const fs::file_time_type saved = fs::last_write_time(state);
  EXPECT_EQ(run("ring.toml", "-t 1 " + ring + " -o " + out.string() + " --resume --pause-at 0.03", &said), 130);
  EXPECT_NE(said.find("stops again before its first step"), std::string::npos) << said;
  EXPECT_EQ(fs::last_write_time(state), saved);

  EXPECT_EQ(run("ring.toml", "-t 1 " + ring + " --set amplitude=0.25 -o " + out.string() + " --resume", &said), 2);
  EXPECT_NE(said.find("another configuration"), std::string::npos) << said;
  EXPECT_NE(said.find("amplitude"), std::string::npos) << said;
  EXPECT_NE(said.find("remove it to start again"), std::string::npos) << said;
  EXPECT_EQ(run("ring.toml", "-t 2 " + ring + " -o " + out.string() + " --resume", &said), 2);
  EXPECT_NE(said.find("another threads"), std::string::npos) << said;
  ASSERT_TRUE(fs::exists(state));

  EXPECT_EQ(run("ring.toml", "-t 2 " + ring + " -o " + out.string() + " --resume-if-same", &said), 0);
  EXPECT_NE(said.find("starting from t = 0"), std::string::npos) << said;
  EXPECT_TRUE(File::open_read(out.string()).root().attribute_doubles("resumed_at").empty());
  EXPECT_FALSE(fs::exists(state));

  std::ofstream(state) << "not a restart file";
  EXPECT_EQ(run("ring.toml", "-t 1 " + ring + " -o " + out.string() + " --resume", &said), 2);
  EXPECT_NE(said.find("cannot be read"), std::string::npos) << said;
  fs::remove(state);

#ifdef MPMVV_HAVE_SUNDIALS
  const fs::path implicit = scratch("implicit.h5");
  EXPECT_EQ(run("hertz-cylinder.toml", "-t 1 --set solver=implicit --set cells=10 -o " + implicit.string() +
                                           " --checkpoint-every 60",
                &said),
            2);
  EXPECT_NE(said.find("explicit runs only"), std::string::npos) << said;
#endif
}

namespace {

// The file offset and size of the largest chunked dataset's first chunk in
// the HDF5 file `path` (H5Dget_chunk_info): where its values lie.
std::pair<haddr_t, hsize_t> largest_chunk(const std::string& path) {
  std::pair<haddr_t, hsize_t> best{0, 0};
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  auto visit = [](hid_t object, const char* name, const H5O_info_t* info, void* data) -> herr_t {
    if (info->type != H5O_TYPE_DATASET) return 0;
    auto& best = *static_cast<std::pair<haddr_t, hsize_t>*>(data);
    const hid_t set = H5Dopen2(object, name, H5P_DEFAULT);
    const hid_t plist = H5Dget_create_plist(set);
    if (H5Pget_layout(plist) == H5D_CHUNKED) {
      hsize_t offset[8] = {}, size = 0;
      unsigned mask = 0;
      haddr_t address = 0;
      const hid_t space = H5Dget_space(set);
      if (H5Dget_chunk_info(set, space, 0, offset, &mask, &address, &size) >= 0 && size > best.second)
        best = {address, size};
      H5Sclose(space);
    }
    H5Pclose(plist);
    H5Dclose(set);
    return 0;
  };
  H5Ovisit(file, H5_INDEX_NAME, H5_ITER_NATIVE, visit, &best);
  H5Fclose(file);
  return best;
}

}  // namespace

// A restart file whose values changed on disk (a flipped byte) is refused,
// not resumed with other numbers: every dataset is under HDF5's Fletcher-32
// checksum (solver/io/hdf5.cpp).
TEST(Restart, AFlippedByteIsAnErrorNotANumber) {
  const std::string ring = "--set cells=24 --set end_time=0.1 --set output_times=[0.1]";
  const fs::path out = scratch("flipped.h5");
  const std::string state = out.string() + ".restart";
  ASSERT_EQ(run("ring.toml", "-t 1 " + ring + " -o " + out.string() + " --pause-at 0.03"), 130);
  const auto [address, size] = largest_chunk(state);
  ASSERT_GT(size, 100u) << "no chunked dataset in " << state;
  {
    std::fstream file(state, std::ios::in | std::ios::out | std::ios::binary);
    file.seekg(std::streamoff(address + size / 2));
    const char byte = char(file.get());
    file.seekp(std::streamoff(address + size / 2));
    file.put(char(byte ^ 0x10));
  }
  std::string said;
  EXPECT_EQ(run("ring.toml", "-t 1 " + ring + " -o " + out.string() + " --resume", &said), 2);
  EXPECT_NE(said.find("cannot be read"), std::string::npos) << said;
  fs::remove(state);
}

// The header's time is an attribute, outside the datasets' checksums: one
// that does not say what the checksummed state says is refused as well.
TEST(Restart, AHeaderThatDisagreesWithItsStateIsRefused) {
  const std::string ring = "--set cells=24 --set end_time=0.1 --set output_times=[0.1]";
  const fs::path out = scratch("header.h5");
  const std::string state = out.string() + ".restart";
  ASSERT_EQ(run("ring.toml", "-t 1 " + ring + " -o " + out.string() + " --pause-at 0.03"), 130);
  {
    const hid_t file = H5Fopen(state.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(file, 0);
    const hid_t time = H5Aopen(file, "time", H5P_DEFAULT);
    double t = 0.0;
    H5Aread(time, H5T_NATIVE_DOUBLE, &t);
    t = std::nextafter(t, 1.0);
    ASSERT_GE(H5Awrite(time, H5T_NATIVE_DOUBLE, &t), 0);
    H5Aclose(time);
    H5Fclose(file);
  }
  std::string said;
  EXPECT_EQ(run("ring.toml", "-t 1 " + ring + " -o " + out.string() + " --resume", &said), 2);
  EXPECT_NE(said.find("its header says t = "), std::string::npos) << said;
  fs::remove(state);
}

namespace {

struct Inner {
  std::vector<double> values;
  std::string label;

  template <class Archive>
  void persist(Archive& a) {
    a.field("values", values);
    a.field("label", label);
  }
};

struct Record {
  double time;
  mpmvv::Vec2 point;
  long long count;
};

}  // namespace

// What the archive writes it reads back into the same members: scalars,
// values of fixed size (Eigen's included), vectors of them, strings, pairs,
// vectors of vectors and objects with state of their own, empty or not; an
// array whose bytes are not a whole number of elements is refused.
TEST(StateArchive, ReadsBackWhatItWrote) {
  const fs::path path = scratch("archive.h5");
  double scalar = -0.1;
  mpmvv::Mat2 matrix;
  matrix << 1.0, 2.0, 3.0, std::numeric_limits<double>::quiet_NaN();
  std::vector<Record> records = {{0.5, mpmvv::Vec2(1.0, -2.0), 7}, {1.5, mpmvv::Vec2(3.0, 4.0), -1}};
  std::vector<std::vector<double>> rows = {{1.0, 2.0}, {}, {3.0}};
  std::pair<std::string, std::string> pair = {"energy blow-up", ""};
  std::vector<Inner> inners = {{{1e-300, 2.0}, "a"}, {{}, ""}};
  std::vector<float> wrong_size = {1.0f, 2.0f, 3.0f};
  {
    File file = File::create(path.string());
    {
      mpmvv::StateArchive a = mpmvv::StateArchive::writing(file.root());
      a.field("scalar", scalar);
      a.field("matrix", matrix);
      a.field("records", records);
      a.field("rows", rows);
      a.field("pair", pair);
      a.field("inners", inners);
      a.field("floats", wrong_size);
    }
    file.save();
  }
  double scalar_read = 0.0;
  mpmvv::Mat2 matrix_read = mpmvv::Mat2::Zero();
  std::vector<Record> records_read;
  std::vector<std::vector<double>> rows_read = {{9.0}};
  std::pair<std::string, std::string> pair_read = {"x", "y"};
  std::vector<Inner> inners_read;
  std::vector<mpmvv::Vec2> wrong_read;
  const File file = File::open_read(path.string());
  mpmvv::StateArchive a = mpmvv::StateArchive::reading(file.root());
  a.field("scalar", scalar_read);
  a.field("matrix", matrix_read);
  a.field("records", records_read);
  a.field("rows", rows_read);
  a.field("pair", pair_read);
  a.field("inners", inners_read);
  EXPECT_EQ(scalar_read, scalar);
  EXPECT_EQ(std::memcmp(matrix.data(), matrix_read.data(), sizeof(mpmvv::Mat2)), 0);
  ASSERT_EQ(records_read.size(), records.size());
  for (std::size_t k = 0; k < records.size(); ++k) {
    EXPECT_EQ(records_read[k].time, records[k].time);
    EXPECT_EQ(records_read[k].point, records[k].point);
    EXPECT_EQ(records_read[k].count, records[k].count);
  }
  EXPECT_EQ(rows_read, rows);
  EXPECT_EQ(pair_read, pair);
  ASSERT_EQ(inners_read.size(), inners.size());
  for (std::size_t k = 0; k < inners.size(); ++k) {
    EXPECT_EQ(inners_read[k].values, inners[k].values);
    EXPECT_EQ(inners_read[k].label, inners[k].label);
  }
  // 12 bytes are not a whole number of 16-byte points.
  EXPECT_THROW(a.field("floats", wrong_read), std::runtime_error);
}
