#include "hdf5.hpp"

#include <sys/mman.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "write_file.hpp"

namespace mpmvv::h5 {

namespace {

// HDF5 prints its own error stack by default; the exceptions below say what
// failed instead.
struct SilenceAutomaticErrorPrinting {
  SilenceAutomaticErrorPrinting() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }
};
const SilenceAutomaticErrorPrinting silence;

[[noreturn]] void fail(const char* call, const std::string& what) {
  throw std::runtime_error(std::string("HDF5 ") + call + " failed on " + what);
}

hid_t check(hid_t id, const char* call, const std::string& what) {
  if (id < 0) fail(call, what);
  return id;
}

void check_status(herr_t status, const char* call, const std::string& what) {
  if (status < 0) fail(call, what);
}

std::string join(const std::string& parent, const std::string& name) {
  return parent == "/" ? "/" + name : parent + "/" + name;
}

Handle scalar_space(const std::string& what) {
  return Handle(check(H5Screate(H5S_SCALAR), "H5Screate", what), H5Sclose);
}

Handle simple_space(const std::vector<hsize_t>& dims, const std::string& what) {
  return Handle(check(H5Screate_simple(int(dims.size()), dims.data(), nullptr), "H5Screate_simple", what),
                H5Sclose);
}

Handle utf8_string_type(const std::string& what) {
  Handle type(check(H5Tcopy(H5T_C_S1), "H5Tcopy", what), H5Tclose);
  check_status(H5Tset_size(type.get(), H5T_VARIABLE), "H5Tset_size", what);
  check_status(H5Tset_cset(type.get(), H5T_CSET_UTF8), "H5Tset_cset", what);
  return type;
}

void write_attribute(hid_t parent, const std::string& name, hid_t type, hid_t space, const void* data,
                     const std::string& what) {
  if (H5Aexists(parent, name.c_str()) > 0)
    check_status(H5Adelete(parent, name.c_str()), "H5Adelete", what);
  Handle attr(check(H5Acreate2(parent, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), "H5Acreate2", what),
              H5Aclose);
  check_status(H5Awrite(attr.get(), type, data), "H5Awrite", what);
}

// HDF5 stamps every object's header with the clock unless told not to; without
// the stamps the same content gives the same bytes, whenever it is written.
void untimed(const Handle& creation_properties, const std::string& what) {
  check_status(H5Pset_obj_track_times(creation_properties.get(), false), "H5Pset_obj_track_times", what);
}

// Rows a chunk holds at most (4 MiB for the widest particle field, 8 doubles
// a row).
constexpr hsize_t kRowsPerChunk = hsize_t(1) << 16;

// The rows of each chunk of a dataset of `rows` rows: as many chunks as
// kRowsPerChunk needs, of equal size. HDF5 stores a chunk whole, so chunks of
// kRowsPerChunk stored 131,072 rows for the ring's 92,500 particles on 256
// cells (a results file with particle_fields = "outputs" grew from 151 to
// 214 MB); equal chunks leave at most one row a chunk unused. write_rows
// writes a chunk a block.
hsize_t chunk_rows(hsize_t rows) {
  const hsize_t chunks = (rows + kRowsPerChunk - 1) / kRowsPerChunk;
  return chunks == 0 ? 0 : (rows + chunks - 1) / chunks;
}

Handle create_dataset(hid_t parent, const std::string& name, hid_t type, const Handle& space,
                      const std::string& what) {
  Handle dcpl(check(H5Pcreate(H5P_DATASET_CREATE), "H5Pcreate", what), H5Pclose);
  untimed(dcpl, what);
  // Every value under HDF5's Fletcher-32 checksum: a flipped bit is an error
  // on reading, not a different number (a restart promises the bits of an
  // uninterrupted run; its state is datasets, state_archive.hpp).
  // The filter needs chunked storage; a scalar or empty dataset has no values
  // to guard.
  const int rank = H5Sget_simple_extent_ndims(space.get());
  std::vector<hsize_t> chunk(std::size_t(std::max(rank, 0)));
  if (rank > 0) check_status(H5Sget_simple_extent_dims(space.get(), chunk.data(), nullptr), "H5Sget_simple_extent_dims", what);
  if (rank > 0 && std::all_of(chunk.begin(), chunk.end(), [](hsize_t d) { return d > 0; })) {
    chunk[0] = chunk_rows(chunk[0]);
    check_status(H5Pset_chunk(dcpl.get(), rank, chunk.data()), "H5Pset_chunk", what);
    check_status(H5Pset_fletcher32(dcpl.get()), "H5Pset_fletcher32", what);
  }
  return Handle(check(H5Dcreate2(parent, name.c_str(), type, space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT),
                      "H5Dcreate2", what),
                H5Dclose);
}

void write_dataset(hid_t parent, const std::string& name, hid_t type, const std::vector<hsize_t>& dims,
                   const void* data, const std::string& what) {
  Handle space = simple_space(dims, what);
  Handle set = create_dataset(parent, name, type, space, what);
  check_status(H5Dwrite(set.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "H5Dwrite", what);
}

}  // namespace

Handle& Handle::operator=(Handle&& o) noexcept {
  if (this != &o) {
    if (id_ >= 0 && closer_) closer_(id_);
    id_ = o.id_;
    closer_ = o.closer_;
    o.id_ = H5I_INVALID_HID;
  }
  return *this;
}

Handle::~Handle() {
  if (id_ >= 0 && closer_) closer_(id_);
}

// Groups remember the order their members were written in, so that readers
// list probe lines and error columns as the scene made them.
Handle ordered_group_properties(const std::string& what) {
  Handle gcpl(check(H5Pcreate(H5P_GROUP_CREATE), "H5Pcreate", what), H5Pclose);
  check_status(H5Pset_link_creation_order(gcpl.get(), H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED),
               "H5Pset_link_creation_order", what);
  untimed(gcpl, what);
  return gcpl;
}

Group Group::create_group(const std::string& name) {
  const std::string p = join(path_, name);
  Handle gcpl = ordered_group_properties(p);
  return Group(Handle(check(H5Gcreate2(id(), name.c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT), "H5Gcreate2", p),
                      H5Gclose),
               p);
}

Group Group::open_group(const std::string& name) const {
  const std::string p = join(path_, name);
  return Group(Handle(check(H5Gopen2(id(), name.c_str(), H5P_DEFAULT), "H5Gopen2", p), H5Gclose), p);
}

bool Group::has(const std::string& name) const {
  const htri_t r = H5Lexists(id(), name.c_str(), H5P_DEFAULT);
  if (r < 0) fail("H5Lexists", join(path_, name));
  return r > 0;
}

bool Group::has_attribute(const std::string& name) const {
  const htri_t r = H5Aexists(id(), name.c_str());
  if (r < 0) fail("H5Aexists", path_ + "@" + name);
  return r > 0;
}

std::vector<std::string> Group::members() const {
  std::vector<std::string> names;
  H5G_info_t info;
  check_status(H5Gget_info(id(), &info), "H5Gget_info", path_);
  // Groups written by mpmvv track creation order; others list by name.
  Handle gcpl(check(H5Gget_create_plist(id()), "H5Gget_create_plist", path_), H5Pclose);
  unsigned flags = 0;
  check_status(H5Pget_link_creation_order(gcpl.get(), &flags), "H5Pget_link_creation_order", path_);
  const H5_index_t index = (flags & H5P_CRT_ORDER_INDEXED) ? H5_INDEX_CRT_ORDER : H5_INDEX_NAME;
  for (hsize_t k = 0; k < info.nlinks; ++k) {
    const ssize_t length = H5Lget_name_by_idx(id(), ".", index, H5_ITER_INC, k, nullptr, 0, H5P_DEFAULT);
    if (length < 0) fail("H5Lget_name_by_idx", path_);
    std::string name(std::size_t(length), '\0');
    if (H5Lget_name_by_idx(id(), ".", index, H5_ITER_INC, k, name.data(), std::size_t(length) + 1, H5P_DEFAULT) < 0)
      fail("H5Lget_name_by_idx", path_);
    names.push_back(name);
  }
  return names;
}

void Group::set_attribute(const std::string& name, double value) {
  const std::string what = path_ + "@" + name;
  Handle space = scalar_space(what);
  write_attribute(id(), name, H5T_NATIVE_DOUBLE, space.get(), &value, what);
}

void Group::set_attribute(const std::string& name, std::int64_t value) {
  const std::string what = path_ + "@" + name;
  Handle space = scalar_space(what);
  write_attribute(id(), name, H5T_NATIVE_INT64, space.get(), &value, what);
}

void Group::set_attribute(const std::string& name, const std::string& value) {
  const std::string what = path_ + "@" + name;
  Handle space = scalar_space(what);
  Handle type = utf8_string_type(what);
  const char* data = value.c_str();
  write_attribute(id(), name, type.get(), space.get(), &data, what);
}

void Group::set_attribute(const std::string& name, const std::vector<double>& values) {
  const std::string what = path_ + "@" + name;
  Handle space = simple_space({hsize_t(values.size())}, what);
  const double none = 0.0;  // HDF5 takes a buffer even for no elements
  write_attribute(id(), name, H5T_NATIVE_DOUBLE, space.get(), values.empty() ? &none : values.data(), what);
}

void Group::write(const std::string& name, const std::vector<double>& data, const std::vector<hsize_t>& dims) {
  write_dataset(id(), name, H5T_NATIVE_DOUBLE, dims, data.data(), join(path_, name));
}

void Group::write(const std::string& name, const std::vector<std::int64_t>& data,
                  const std::vector<hsize_t>& dims) {
  write_dataset(id(), name, H5T_NATIVE_INT64, dims, data.data(), join(path_, name));
}

void Group::write_bytes(const std::string& name, const void* data, std::size_t size) {
  // HDF5 takes a buffer even for no elements.
  const unsigned char none = 0;
  write_dataset(id(), name, H5T_NATIVE_UCHAR, {hsize_t(size)}, size ? data : &none, join(path_, name));
}

void Group::write_rows(const std::string& name, const std::vector<hsize_t>& dims, const RowFiller& fill) {
  const std::string what = join(path_, name);
  if (dims.empty()) throw std::invalid_argument("HDF5 dataset " + what + " written by rows has no dimensions");
  Handle space = simple_space(dims, what);
  Handle set = create_dataset(id(), name, H5T_NATIVE_DOUBLE, space, what);
  const hsize_t rows = dims[0];
  hsize_t row_size = 1;
  for (std::size_t k = 1; k < dims.size(); ++k) row_size *= dims[k];
  // A chunk a block (chunk_rows).
  const hsize_t kBlock = std::max<hsize_t>(chunk_rows(rows), 1);
  std::vector<double> block(std::size_t(std::min(rows, kBlock) * row_size));
  std::vector<hsize_t> start(dims.size(), 0), count(dims);
  for (hsize_t first = 0; first < rows; first += kBlock) {
    count[0] = std::min(kBlock, rows - first);
    start[0] = first;
    fill(std::size_t(first), std::size_t(count[0]), block.data());
    check_status(H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr),
                 "H5Sselect_hyperslab", what);
    Handle memory = simple_space(count, what);
    check_status(H5Dwrite(set.get(), H5T_NATIVE_DOUBLE, memory.get(), space.get(), H5P_DEFAULT, block.data()),
                 "H5Dwrite", what);
  }
}

double Group::attribute_double(const std::string& name) const {
  const std::string what = path_ + "@" + name;
  Handle attr(check(H5Aopen(id(), name.c_str(), H5P_DEFAULT), "H5Aopen", what), H5Aclose);
  double v = 0.0;
  check_status(H5Aread(attr.get(), H5T_NATIVE_DOUBLE, &v), "H5Aread", what);
  return v;
}

std::vector<double> Group::attribute_doubles(const std::string& name) const {
  const std::string what = path_ + "@" + name;
  Handle attr(check(H5Aopen(id(), name.c_str(), H5P_DEFAULT), "H5Aopen", what), H5Aclose);
  Handle space(check(H5Aget_space(attr.get()), "H5Aget_space", what), H5Sclose);
  const hssize_t count = H5Sget_simple_extent_npoints(space.get());
  if (count < 0) fail("H5Sget_simple_extent_npoints", what);
  std::vector<double> values(static_cast<std::size_t>(count));
  if (count > 0) check_status(H5Aread(attr.get(), H5T_NATIVE_DOUBLE, values.data()), "H5Aread", what);
  return values;
}

std::int64_t Group::attribute_int(const std::string& name) const {
  const std::string what = path_ + "@" + name;
  Handle attr(check(H5Aopen(id(), name.c_str(), H5P_DEFAULT), "H5Aopen", what), H5Aclose);
  std::int64_t v = 0;
  check_status(H5Aread(attr.get(), H5T_NATIVE_INT64, &v), "H5Aread", what);
  return v;
}

std::string Group::attribute_string(const std::string& name) const {
  const std::string what = path_ + "@" + name;
  Handle attr(check(H5Aopen(id(), name.c_str(), H5P_DEFAULT), "H5Aopen", what), H5Aclose);
  Handle type = utf8_string_type(what);
  char* data = nullptr;
  check_status(H5Aread(attr.get(), type.get(), &data), "H5Aread", what);
  std::string value = data ? data : "";
  H5free_memory(data);
  return value;
}

std::vector<hsize_t> Group::dimensions(const std::string& name) const {
  const std::string what = join(path_, name);
  Handle set(check(H5Dopen2(id(), name.c_str(), H5P_DEFAULT), "H5Dopen2", what), H5Dclose);
  Handle space(check(H5Dget_space(set.get()), "H5Dget_space", what), H5Sclose);
  const int rank = check(H5Sget_simple_extent_ndims(space.get()), "H5Sget_simple_extent_ndims", what);
  std::vector<hsize_t> d(std::size_t(rank), 0);
  check(H5Sget_simple_extent_dims(space.get(), d.data(), nullptr), "H5Sget_simple_extent_dims", what);
  return d;
}

std::vector<double> Group::read_doubles(const std::string& name, std::vector<hsize_t>* dims) const {
  const std::string what = join(path_, name);
  const std::vector<hsize_t> d = dimensions(name);
  Handle set(check(H5Dopen2(id(), name.c_str(), H5P_DEFAULT), "H5Dopen2", what), H5Dclose);
  hsize_t count = 1;
  for (hsize_t x : d) count *= x;
  std::vector<double> data(count);
  if (count > 0)
    check_status(H5Dread(set.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()), "H5Dread", what);
  if (dims) *dims = d;
  return data;
}

Group::StoredNumber Group::stored_number(const std::string& name) const {
  const std::string what = join(path_, name);
  Handle set(check(H5Dopen2(id(), name.c_str(), H5P_DEFAULT), "H5Dopen2", what), H5Dclose);
  Handle type(check(H5Dget_type(set.get()), "H5Dget_type", what), H5Tclose);
  const H5T_class_t kind = H5Tget_class(type.get());
  if (kind == H5T_NO_CLASS) fail("H5Tget_class", what);
  const std::size_t bytes = H5Tget_size(type.get());
  if (bytes == 0) fail("H5Tget_size", what);
  return {kind == H5T_FLOAT, bytes};
}

bool Group::is_group(const std::string& name) const {
  const std::string what = join(path_, name);
  Handle object(check(H5Oopen(id(), name.c_str(), H5P_DEFAULT), "H5Oopen", what), H5Oclose);
  const H5I_type_t type = H5Iget_type(object.get());
  if (type == H5I_BADID) fail("H5Iget_type", what);
  return type == H5I_GROUP;
}

std::size_t Group::byte_count(const std::string& name) const {
  const std::string what = join(path_, name);
  Handle set(check(H5Dopen2(id(), name.c_str(), H5P_DEFAULT), "H5Dopen2", what), H5Dclose);
  Handle space(check(H5Dget_space(set.get()), "H5Dget_space", what), H5Sclose);
  const hssize_t count = H5Sget_simple_extent_npoints(space.get());
  if (count < 0) fail("H5Sget_simple_extent_npoints", what);
  return std::size_t(count);
}

void Group::read_bytes(const std::string& name, void* out, std::size_t size) const {
  const std::string what = join(path_, name);
  if (const std::size_t stored = byte_count(name); stored != size)
    throw std::runtime_error("HDF5 dataset " + what + " holds " + std::to_string(stored) + " bytes, not " +
                             std::to_string(size));
  Handle set(check(H5Dopen2(id(), name.c_str(), H5P_DEFAULT), "H5Dopen2", what), H5Dclose);
  if (size > 0)
    check_status(H5Dread(set.get(), H5T_NATIVE_UCHAR, H5S_ALL, H5S_ALL, H5P_DEFAULT, out), "H5Dread", what);
}

// The core driver's buffer, allocated through the file image callbacks
// (H5Pset_file_image_callbacks) so that HDF5 hands it over when the file
// closes instead of freeing it: by then the library has flushed every
// object and cleared the superblock's status flags, so the buffer's first
// bytes, as many as the image had before the close, are the file exactly as H5Fget_file_image would copy it
// (tests/test_results_file.cpp checks this).
namespace {

// The buffer lives in pages of its own and grows by mremap, which moves
// pages instead of copying bytes. Grown a MiB at a time by realloc, a heap
// block is copied whenever it cannot grow in place, and the copies left
// behind stay resident: measured on 2.0 M particles, 40 MB above the
// file's 193 MB. The mapping's length sits in a header before the image.
constexpr std::size_t kHeader = 64;

void* map_image(std::size_t size) {
  const std::size_t length = size + kHeader;
  void* base = ::mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (base == MAP_FAILED) return nullptr;
  *static_cast<std::size_t*>(base) = length;
  return static_cast<char*>(base) + kHeader;
}

void unmap_image(void* image) {
  if (image == nullptr) return;
  char* base = static_cast<char*>(image) - kHeader;
  ::munmap(base, *reinterpret_cast<std::size_t*>(base));
}

void* remap_image(void* image, std::size_t size) {
  if (image == nullptr) return map_image(size);
  char* base = static_cast<char*>(image) - kHeader;
  const std::size_t length = size + kHeader;
  void* moved = ::mremap(base, *reinterpret_cast<std::size_t*>(base), length, MREMAP_MAYMOVE);
  if (moved == MAP_FAILED) return nullptr;
  *static_cast<std::size_t*>(moved) = length;
  return static_cast<char*>(moved) + kHeader;
}

}  // namespace

struct CoreImage {
  void* data = nullptr;  // set when the file closes
  ~CoreImage() { unmap_image(data); }
};

namespace {

void* image_malloc(std::size_t size, H5FD_file_image_op_t, void*) { return map_image(size); }
void* image_memcpy(void* dest, const void* src, std::size_t size, H5FD_file_image_op_t, void*) {
  return std::memcpy(dest, src, size);
}
void* image_realloc(void* ptr, std::size_t size, H5FD_file_image_op_t, void*) { return remap_image(ptr, size); }
herr_t image_free(void* ptr, H5FD_file_image_op_t op, void* udata) {
  auto* image = static_cast<CoreImage*>(udata);
  if (op == H5FD_FILE_IMAGE_OP_FILE_CLOSE && image != nullptr && image->data == nullptr) {
    image->data = ptr;
    return 0;
  }
  unmap_image(ptr);
  return 0;
}
// The property list copies its callbacks' user data; every copy points at
// the one CoreImage the File owns.
void* udata_copy(void* udata) { return udata; }
herr_t udata_free(void*) { return 0; }

}  // namespace

File::File(Handle handle, std::string path, std::unique_ptr<CoreImage> image)
    : image_(std::move(image)), handle_(std::move(handle)), path_(std::move(path)) {}
File::File(File&&) noexcept = default;
File& File::operator=(File&&) noexcept = default;
File::~File() = default;

File File::create(const std::string& path) {
  Handle fcpl(check(H5Pcreate(H5P_FILE_CREATE), "H5Pcreate", path), H5Pclose);
  check_status(H5Pset_link_creation_order(fcpl.get(), H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED),
               "H5Pset_link_creation_order", path);
  untimed(fcpl, path);  // the root group's header
  Handle fapl(check(H5Pcreate(H5P_FILE_ACCESS), "H5Pcreate", path), H5Pclose);
  // In memory, grown a MiB at a time, with no backing store: save() writes it.
  check_status(H5Pset_fapl_core(fapl.get(), std::size_t(1) << 20, 0), "H5Pset_fapl_core", path);
  // Closing the file closes whatever is still open in it, so the buffer is
  // always handed over while its CoreImage exists.
  check_status(H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG), "H5Pset_fclose_degree", path);
  auto image = std::make_unique<CoreImage>();
  H5FD_file_image_callbacks_t callbacks = {image_malloc, image_memcpy, image_realloc, image_free,
                                           udata_copy,   udata_free,   image.get()};
  check_status(H5Pset_file_image_callbacks(fapl.get(), &callbacks), "H5Pset_file_image_callbacks", path);
  Handle file(check(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, fcpl.get(), fapl.get()), "H5Fcreate", path), H5Fclose);
  return File(std::move(file), path, std::move(image));
}

File File::open_read(const std::string& path) {
  return File(Handle(check(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), "H5Fopen", path), H5Fclose), path,
              nullptr);
}

Group File::root() const {
  return Group(Handle(check(H5Gopen2(handle_.get(), "/", H5P_DEFAULT), "H5Gopen2", path_ + ":/"), H5Gclose), "/");
}

void File::save() {
  if (!image_) throw std::logic_error("HDF5 file " + path_ + " was opened for reading and cannot be saved");
  const hid_t id = handle_.get();
  // A group still open would be closed under its owner (the close degree is
  // strong), whose own close would then act on a dead handle: refused.
  const ssize_t open_objects = H5Fget_obj_count(id, H5F_OBJ_ALL | H5F_OBJ_LOCAL);
  if (open_objects < 0) fail("H5Fget_obj_count", path_);
  if (open_objects != 1)
    throw std::logic_error("HDF5 file " + path_ + " saved with " + std::to_string(open_objects - 1) +
                           " of its objects still open");
  check_status(H5Fflush(id, H5F_SCOPE_GLOBAL), "H5Fflush", path_);
  // The image's length (HDF5's end of allocation), which the close leaves as it is.
  const ssize_t size = H5Fget_file_image(id, nullptr, 0);
  if (size < 0) fail("H5Fget_file_image", path_);
  check_status(H5Fclose(handle_.release()), "H5Fclose", path_);
  if (image_->data == nullptr) fail("H5Fclose (the core driver's buffer was not handed over)", path_);
  io::write_file(path_, image_->data, std::size_t(size));
  image_.reset();
}

}  // namespace mpmvv::h5
