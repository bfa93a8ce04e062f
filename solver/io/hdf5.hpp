// A thin owner of HDF5 handles. Every library call is checked; a failing call
// throws with the call's name and the object it was working on.
#pragma once

#include <hdf5.h>

#include <cstdint>
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

  double attribute_double(const std::string& name) const;
  std::vector<double> attribute_doubles(const std::string& name) const;
  std::int64_t attribute_int(const std::string& name) const;
  std::string attribute_string(const std::string& name) const;
  std::vector<double> read_doubles(const std::string& name, std::vector<hsize_t>* dims = nullptr) const;

 private:
  Handle handle_;
  std::string path_;
};

class File {
 public:
  // A new file, built in memory (HDF5's core driver) and written to `path`
  // by save(): HDF5 itself never writes to the disk, so a full disk is one
  // checked write (io/write_file.hpp), not a failed flush that HDF5 retries,
  // and crashes on, when the library shuts down.
  static File create(const std::string& path);
  static File open_read(const std::string& path);
  Group root() const;
  const std::string& path() const { return path_; }
  // Writes the file's image to its path (create) or flushes it (open_read).
  void save() const;

 private:
  File(Handle handle, std::string path, bool in_memory = false)
      : handle_(std::move(handle)), path_(std::move(path)), in_memory_(in_memory) {}
  Handle handle_;
  std::string path_;
  bool in_memory_;
};

}  // namespace mpmvv::h5
