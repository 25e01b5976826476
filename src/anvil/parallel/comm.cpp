#include "anvil/parallel/comm.hpp"

#include <mpi.h>

#include <climits>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace anvil {

static_assert(sizeof(MPI_Comm) <= sizeof(void*), "MPI_Comm must fit in a pointer");

namespace {

MPI_Comm to_mpi(void* h) {
  MPI_Comm c;
  std::memcpy(&c, &h, sizeof(MPI_Comm));
  return c;
}
void* from_mpi(MPI_Comm c) {
  void* h = nullptr;
  std::memcpy(&h, &c, sizeof(MPI_Comm));
  return h;
}
void check(int rc, const char* what) {
  if (rc != MPI_SUCCESS) throw std::runtime_error(std::string("MPI failure in ") + what);
}
int to_int(std::size_t n, const char* what) {
  if (n > static_cast<std::size_t>(INT_MAX))
    throw std::runtime_error(std::string("message too large in ") + what);
  return static_cast<int>(n);
}

} // namespace

MpiSession::MpiSession(int* argc, char*** argv) {
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (!initialised) {
    // Open MPI's shared-memory transport sends a message longer than its eager limit (4 KiB
    // by default) by rendezvous: the sender's wait ends only after the receiver has matched
    // the message, pulled it and answered, one more round trip between the ranks. The
    // messages of a lazy contact cycle and the corner exchange of a 1875-element rank are
    // 0.2-11 KB (34 KB with the paper's decompositions; a full contact cycle's up to 92 KB;
    // docs/performance.md, "Messages"): at 32 KiB, the transport's own fragment size
    // (btl_vader_max_send_size), the common ones go eagerly. A value the user gave (mpirun
    // --mca, or the environment) stands; other MPI libraries ignore the variable.
    setenv("OMPI_MCA_btl_vader_eager_limit", "32768", 0);
    MPI_Init(argc, argv);
  }
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
}

MpiSession::~MpiSession() {
  int finalised = 0;
  MPI_Finalized(&finalised);
  if (!finalised) MPI_Finalize();
}

struct Requests::Impl {
  std::vector<MPI_Request> list;
};
Requests::Requests() : impl_(std::make_unique<Impl>()) {}
Requests::~Requests() {
  if (impl_ && !impl_->list.empty())
    MPI_Waitall(static_cast<int>(impl_->list.size()), impl_->list.data(), MPI_STATUSES_IGNORE);
}
Requests::Requests(Requests&&) noexcept = default;
Requests& Requests::operator=(Requests&&) noexcept = default;
void Requests::wait() {
  if (impl_->list.empty()) return;
  check(MPI_Waitall(static_cast<int>(impl_->list.size()), impl_->list.data(), MPI_STATUSES_IGNORE),
        "MPI_Waitall");
  impl_->list.clear();
}
std::size_t Requests::size() const {
  return impl_->list.size();
}

Comm::Comm(void* handle, bool owned) : handle_(handle), owned_(owned) {
  MPI_Comm c = to_mpi(handle_);
  MPI_Comm_rank(c, &rank_);
  MPI_Comm_size(c, &size_);
}
Comm Comm::world() {
  return Comm(from_mpi(MPI_COMM_WORLD), false);
}
Comm Comm::self() {
  return Comm(from_mpi(MPI_COMM_SELF), false);
}
Comm::Comm(Comm&& o) noexcept
    : handle_(o.handle_), owned_(o.owned_), rank_(o.rank_), size_(o.size_) {
  o.handle_ = nullptr;
  o.owned_ = false;
}
Comm& Comm::operator=(Comm&& o) noexcept {
  if (this != &o) {
    if (owned_ && handle_) {
      MPI_Comm c = to_mpi(handle_);
      MPI_Comm_free(&c);
    }
    handle_ = o.handle_;
    owned_ = o.owned_;
    rank_ = o.rank_;
    size_ = o.size_;
    o.handle_ = nullptr;
    o.owned_ = false;
  }
  return *this;
}
Comm::~Comm() {
  if (owned_ && handle_) {
    int finalised = 0;
    MPI_Finalized(&finalised);
    if (!finalised) {
      MPI_Comm c = to_mpi(handle_);
      MPI_Comm_free(&c);
    }
  }
}

Comm Comm::split(int color, int key) const {
  MPI_Comm out;
  check(MPI_Comm_split(to_mpi(handle_), color, key, &out), "MPI_Comm_split");
  return Comm(from_mpi(out), true);
}
Comm Comm::duplicate() const {
  MPI_Comm out;
  check(MPI_Comm_dup(to_mpi(handle_), &out), "MPI_Comm_dup");
  return Comm(from_mpi(out), true);
}

void Comm::barrier() const {
  check(MPI_Barrier(to_mpi(handle_)), "MPI_Barrier");
}
void Comm::abort(int status) const {
  MPI_Abort(to_mpi(handle_), status);
  std::abort();
}

namespace {
template <class T>
MPI_Datatype mpi_type();
template <>
MPI_Datatype mpi_type<double>() {
  return MPI_DOUBLE;
}
template <>
MPI_Datatype mpi_type<std::int64_t>() {
  return MPI_INT64_T;
}

template <class T>
void reduce(void* h, std::span<T> v, MPI_Op op) {
  if (v.empty()) return;
  check(MPI_Allreduce(MPI_IN_PLACE, v.data(), to_int(v.size(), "allreduce"), mpi_type<T>(), op,
                      to_mpi(h)),
        "MPI_Allreduce");
}
} // namespace

void Comm::sum(std::span<double> v) const {
  reduce(handle_, v, MPI_SUM);
}
void Comm::sum(std::span<std::int64_t> v) const {
  reduce(handle_, v, MPI_SUM);
}
void Comm::min(std::span<double> v) const {
  reduce(handle_, v, MPI_MIN);
}
void Comm::max(std::span<double> v) const {
  reduce(handle_, v, MPI_MAX);
}
void Comm::min(std::span<std::int64_t> v) const {
  reduce(handle_, v, MPI_MIN);
}
void Comm::max(std::span<std::int64_t> v) const {
  reduce(handle_, v, MPI_MAX);
}

std::int64_t Comm::exclusive_scan(std::int64_t v) const {
  std::int64_t out = 0;
  check(MPI_Exscan(&v, &out, 1, MPI_INT64_T, MPI_SUM, to_mpi(handle_)), "MPI_Exscan");
  return rank_ == 0 ? 0 : out;
}

void Comm::broadcast_bytes(void* data, std::size_t bytes, int root) const {
  check(MPI_Bcast(data, to_int(bytes, "broadcast"), MPI_BYTE, root, to_mpi(handle_)), "MPI_Bcast");
}
void Comm::broadcast(std::string& s, int root) const {
  std::int64_t n = static_cast<std::int64_t>(s.size());
  broadcast(n, root);
  s.resize(static_cast<std::size_t>(n));
  if (n > 0) broadcast_bytes(s.data(), s.size(), root);
}
void Comm::allgather_bytes(const void* send, std::size_t bytes, void* recv) const {
  const int n = to_int(bytes, "allgather");
  check(MPI_Allgather(send, n, MPI_BYTE, recv, n, MPI_BYTE, to_mpi(handle_)), "MPI_Allgather");
}
void Comm::allgatherv_bytes(const void* send, std::size_t bytes, void* recv,
                            std::span<const std::int64_t> recv_bytes) const {
  std::vector<int>& counts = gather_counts_;
  std::vector<int>& displ = gather_displ_;
  counts.resize(static_cast<std::size_t>(size_));
  displ.resize(counts.size());
  std::int64_t offset = 0;
  for (std::size_t q = 0; q < counts.size(); ++q) {
    counts[q] = to_int(static_cast<std::size_t>(recv_bytes[q]), "allgatherv");
    displ[q] = to_int(static_cast<std::size_t>(offset), "allgatherv");
    offset += recv_bytes[q];
  }
  check(MPI_Allgatherv(send, to_int(bytes, "allgatherv"), MPI_BYTE, recv, counts.data(),
                       displ.data(), MPI_BYTE, to_mpi(handle_)),
        "MPI_Allgatherv");
}
void Comm::alltoall_bytes(const void* send, std::size_t bytes, void* recv) const {
  const int n = to_int(bytes, "alltoall");
  check(MPI_Alltoall(send, n, MPI_BYTE, recv, n, MPI_BYTE, to_mpi(handle_)), "MPI_Alltoall");
}
void Comm::alltoallv_bytes(const void* send, std::span<const std::int64_t> send_bytes,
                           std::span<const std::int64_t> send_displ, void* recv,
                           std::span<const std::int64_t> recv_bytes,
                           std::span<const std::int64_t> recv_displ) const {
  // Point-to-point rather than MPI_Alltoallv: no int overflow of displacements, and only
  // the ranks that exchange data are touched.
  Requests r;
  for (int q = 0; q < size_; ++q)
    if (recv_bytes[q] > 0)
      irecv_bytes(static_cast<char*>(recv) + recv_displ[q], static_cast<std::size_t>(recv_bytes[q]),
                  q, 7001, r);
  for (int q = 0; q < size_; ++q)
    if (send_bytes[q] > 0)
      isend_bytes(static_cast<const char*>(send) + send_displ[q],
                  static_cast<std::size_t>(send_bytes[q]), q, 7001, r);
  r.wait();
}
void Comm::send_bytes(const void* data, std::size_t bytes, int dest, int tag) const {
  check(MPI_Send(data, to_int(bytes, "send"), MPI_BYTE, dest, tag, to_mpi(handle_)), "MPI_Send");
}
void Comm::recv_bytes(void* data, std::size_t bytes, int source, int tag) const {
  check(MPI_Recv(data, to_int(bytes, "recv"), MPI_BYTE, source, tag, to_mpi(handle_),
                 MPI_STATUS_IGNORE),
        "MPI_Recv");
}
void Comm::sendrecv_bytes(const void* send, std::size_t send_bytes, int dest, void* recv,
                          std::size_t recv_bytes, int source, int tag) const {
  check(MPI_Sendrecv(send, to_int(send_bytes, "sendrecv"), MPI_BYTE, dest, tag, recv,
                     to_int(recv_bytes, "sendrecv"), MPI_BYTE, source, tag, to_mpi(handle_),
                     MPI_STATUS_IGNORE),
        "MPI_Sendrecv");
}
void Comm::isend_bytes(const void* data, std::size_t bytes, int dest, int tag, Requests& r) const {
  MPI_Request req;
  check(MPI_Isend(data, to_int(bytes, "isend"), MPI_BYTE, dest, tag, to_mpi(handle_), &req),
        "MPI_Isend");
  r.impl_->list.push_back(req);
}
void Comm::irecv_bytes(void* data, std::size_t bytes, int source, int tag, Requests& r) const {
  MPI_Request req;
  check(MPI_Irecv(data, to_int(bytes, "irecv"), MPI_BYTE, source, tag, to_mpi(handle_), &req),
        "MPI_Irecv");
  r.impl_->list.push_back(req);
}

} // namespace anvil
