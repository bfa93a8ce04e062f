// A run's state written to a restart file and read back into the same
// objects, so that a run stopped at step n and continued from its file ends
// with the bits of one run that never stopped. Each class lists its state
// once, in a persist(StateArchive&) member: the list that writes is the list
// that reads, so the two cannot drift apart.
//
// Members are stored as their bytes, one HDF5 dataset each: a restart file is
// read back only by the build that wrote it (the run refuses another: it
// would not continue with the same bits anyway), and bytes keep every double
// exact without a type per member.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "hdf5.hpp"

namespace mpmvv {

// A value that is its bytes: no heap storage of its own (what std::vector or
// std::string would own) and no pointers. Eigen's fixed-size matrices are such
// values though their copy constructors are not trivial.
template <class T>
concept StoredAsBytes = std::is_trivially_destructible_v<T> && !std::is_pointer_v<T>;

class StateArchive {
 public:
  static StateArchive writing(h5::Group group) { return StateArchive(std::move(group), false); }
  static StateArchive reading(h5::Group group) { return StateArchive(std::move(group), true); }

  bool reads() const { return reading_; }

  template <StoredAsBytes T>
  void field(const std::string& name, T& value) {
    if (reading_)
      group_.read_bytes(name, &value, sizeof(T));
    else
      group_.write_bytes(name, &value, sizeof(T));
  }

  template <StoredAsBytes T>
  void field(const std::string& name, std::vector<T>& values) {
    if (!reading_) {
      group_.write_bytes(name, values.data(), values.size() * sizeof(T));
      return;
    }
    const std::size_t bytes = group_.byte_count(name);
    if (bytes % sizeof(T) != 0)
      throw std::runtime_error("restart file: " + group_.path() + "/" + name + " holds " + std::to_string(bytes) +
                               " bytes, not a whole number of its " + std::to_string(sizeof(T)) + "-byte elements");
    values.resize(bytes / sizeof(T));
    group_.read_bytes(name, values.data(), bytes);
  }

  void field(const std::string& name, std::string& text) {
    if (!reading_) {
      group_.write_bytes(name, text.data(), text.size());
      return;
    }
    text.resize(group_.byte_count(name));
    group_.read_bytes(name, text.data(), text.size());
  }

  // A vector of anything with a field of its own (a vector, a string), its
  // elements named 0, 1, ... in a group.
  template <class T>
  void field(const std::string& name, std::vector<T>& values)
    requires(!StoredAsBytes<T>)
  {
    StateArchive inner = nested(name);
    std::size_t count = values.size();
    inner.field("count", count);
    values.resize(count);
    for (std::size_t k = 0; k < count; ++k) inner.field(std::to_string(k), values[k]);
  }

  template <class A, class B>
  void field(const std::string& name, std::pair<A, B>& pair) {
    StateArchive inner = nested(name);
    inner.field("first", pair.first);
    inner.field("second", pair.second);
  }

  // A member's own state in a group of its name (an object with a
  // persist(StateArchive&) member).
  template <class T>
  void field(const std::string& name, T& object)
    requires(!StoredAsBytes<T>) && requires(T& t, StateArchive& a) { t.persist(a); }
  {
    StateArchive inner = nested(name);
    object.persist(inner);
  }

  StateArchive nested(const std::string& name) {
    return StateArchive(reading_ ? group_.open_group(name) : group_.create_group(name), reading_);
  }

 private:
  StateArchive(h5::Group group, bool reading) : group_(std::move(group)), reading_(reading) {}
  h5::Group group_;
  bool reading_;
};

}  // namespace mpmvv
