// A thin owner of HDF5 handles. Every library call is checked; a failing call
// throws with the call's name and the object it was working on.
#pragma once

#include <hdf5.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace mpmvv::h5 {

// Owns one hid_t and closes it with the matching H5*close.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& o) noexcept : id_(o.id_), closer_(o.closer_) { o.id_ = H5I_INVALID_HID; }
  Handle& operator=(Handle&& o) noexcept;
  ~Handle();
  hid_t get() const { return id_; }
  // Gives up ownership: the caller closes the id.
  hid_t release() {
    const hid_t id = id_;
    id_ = H5I_INVALID_HID;
    return id;
  }

 private:
  hid_t id_ = H5I_INVALID_HID;
  Closer closer_ = nullptr;
};

class Group {
 public:
  Group(Handle handle, std::string path) : handle_(std::move(handle)), path_(std::move(path)) {}
  hid_t id() const { return handle_.get(); }
  const std::string& path() const { return path_; }

  Group create_group(const std::string& name);
  Group open_group(const std::string& name) const;
  bool has(const std::string& name) const;
  // Whether the member `name` is a group (else a dataset).
  bool is_group(const std::string& name) const;
  bool has_attribute(const std::string& name) const;
  // Names of the group's members, in the order they were written.
  std::vector<std::string> members() const;

  void set_attribute(const std::string& name, double value);
  void set_attribute(const std::string& name, std::int64_t value);
  void set_attribute(const std::string& name, const std::string& value);
  void set_attribute(const std::string& name, const char* value) { set_attribute(name, std::string(value)); }
  void set_attribute(const std::string& name, const std::vector<double>& values);

  // Row-major data with the given dimensions (their product is data.size()).
  void write(const std::string& name, const std::vector<double>& data, const std::vector<hsize_t>& dims);
  void write(const std::string& name, const std::vector<std::int64_t>& data, const std::vector<hsize_t>& dims);
  // A dataset of dims[0] rows written a block of rows at a time, so that a
  // large array is never staged whole: fill(first, count, out) writes rows
  // [first, first + count) row-major to out (count * the product of the
  // other dims doubles).
  using RowFiller = std::function<void(std::size_t first, std::size_t count, double* out)>;
  void write_rows(const std::string& name, const std::vector<hsize_t>& dims, const RowFiller& fill);
  // A one-dimensional dataset of `size` bytes, for what only the build that
  // wrote it reads back (a restart file: io/state_archive.hpp).
  void write_bytes(const std::string& name, const void* data, std::size_t size);

  double attribute_double(const std::string& name) const;
  std::vector<double> attribute_doubles(const std::string& name) const;
  std::int64_t attribute_int(const std::string& name) const;
  std::string attribute_string(const std::string& name) const;
  std::vector<double> read_doubles(const std::string& name, std::vector<hsize_t>* dims = nullptr) const;
  // A dataset's dimensions, without reading it.
  std::vector<hsize_t> dimensions(const std::string& name) const;
  // How a dataset's numbers are stored: floating point or integer, and their size in bytes.
  struct StoredNumber {
    bool floating = true;
    std::size_t bytes = 8;
  };
  StoredNumber stored_number(const std::string& name) const;
  // The length of a dataset of bytes, and its bytes into `out` (`size` of
  // them, which must be its length).
  std::size_t byte_count(const std::string& name) const;
  void read_bytes(const std::string& name, void* out, std::size_t size) const;

 private:
  Handle handle_;
  std::string path_;
};

// Where the core driver's buffer lands when HDF5 hands it over (hdf5.cpp).
struct CoreImage;

class File {
 public:
  // A new file, built in memory (HDF5's core driver) and written to `path`
  // by save(): HDF5 itself never writes to the disk, so a full disk is one
  // checked write (io/write_file.hpp), not a failed flush that HDF5 retries,
  // and crashes on, when the library shuts down.
  static File create(const std::string& path);
  static File open_read(const std::string& path);
  File(File&&) noexcept;
  File& operator=(File&&) noexcept;
  ~File();
  Group root() const;
  const std::string& path() const { return path_; }
  // Closes a created file and writes it to its path. HDF5 hands the core
  // driver's buffer over as the file closes, so the file's bytes are never
  // held twice (a copy of the image would double the memory of a run whose
  // particles are most of its file). Every group opened from the file must
  // be closed before; the file is unusable after.
  void save();

 private:
  File(Handle handle, std::string path, std::unique_ptr<CoreImage> image);
  // Declared first so that it outlives the handle: closing the file hands
  // the buffer to it. Null for open_read.
  std::unique_ptr<CoreImage> image_;
  Handle handle_;
  std::string path_;
};

}  // namespace mpmvv::h5
