// Comm: the only door to MPI (the only file pair that includes <mpi.h>). Everything else
// talks to other ranks through this small, typed interface, so physics code never
// depends on MPI and tests can run a whole simulation on MPI_COMM_SELF.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

namespace anvil {

// Initialises MPI for the lifetime of the object (one per process, in main()).
class MpiSession {
public:
  MpiSession(int* argc, char*** argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
};

// Outstanding non-blocking operations; wait() completes them all.
class Requests {
public:
  Requests();
  ~Requests();
  Requests(Requests&&) noexcept;
  Requests& operator=(Requests&&) noexcept;
  void wait();
  std::size_t size() const;

private:
  friend class Comm;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class Comm {
public:
  static Comm world();
  static Comm self();
  Comm(Comm&&) noexcept;
  Comm& operator=(Comm&&) noexcept;
  ~Comm();
  Comm(const Comm&) = delete;
  Comm& operator=(const Comm&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }

  // A sub-communicator of the ranks passing the same color, ordered by key (MPI_Comm_split).
  Comm split(int color, int key) const;
  Comm duplicate() const;

  void barrier() const;
  // Aborts every rank (for unrecoverable states only; errors normally propagate).
  [[noreturn]] void abort(int status) const;

  // Element-wise reductions in place, result on every rank.
  void sum(std::span<double> v) const;
  void sum(std::span<std::int64_t> v) const;
  void min(std::span<double> v) const;
  void max(std::span<double> v) const;
  void min(std::span<std::int64_t> v) const;
  void max(std::span<std::int64_t> v) const;
  double sum(double v) const {
    sum(std::span<double>(&v, 1));
    return v;
  }
  double min(double v) const {
    min(std::span<double>(&v, 1));
    return v;
  }
  double max(double v) const {
    max(std::span<double>(&v, 1));
    return v;
  }
  std::int64_t sum(std::int64_t v) const {
    sum(std::span<std::int64_t>(&v, 1));
    return v;
  }
  std::int64_t min(std::int64_t v) const {
    min(std::span<std::int64_t>(&v, 1));
    return v;
  }
  std::int64_t max(std::int64_t v) const {
    max(std::span<std::int64_t>(&v, 1));
    return v;
  }
  // Exclusive prefix sum over ranks (rank 0 gets 0).
  std::int64_t exclusive_scan(std::int64_t v) const;

  // Raw byte transfers; the typed templates below are the intended interface.
  void broadcast_bytes(void* data, std::size_t bytes, int root) const;
  void allgather_bytes(const void* send, std::size_t bytes_per_rank, void* recv) const;
  // Each rank's `bytes` bytes, concatenated in rank order into recv (sum of recv_bytes).
  void allgatherv_bytes(const void* send, std::size_t bytes, void* recv,
                        std::span<const std::int64_t> recv_bytes) const;
  void alltoall_bytes(const void* send, std::size_t bytes_per_rank, void* recv) const;
  // Variable all-to-all in bytes: counts and displacements per rank.
  void alltoallv_bytes(const void* send, std::span<const std::int64_t> send_bytes,
                       std::span<const std::int64_t> send_displ, void* recv,
                       std::span<const std::int64_t> recv_bytes,
                       std::span<const std::int64_t> recv_displ) const;
  void send_bytes(const void* data, std::size_t bytes, int dest, int tag) const;
  void recv_bytes(void* data, std::size_t bytes, int source, int tag) const;
  // Simultaneous send and receive (for exchanges with a partner).
  void sendrecv_bytes(const void* send, std::size_t send_bytes, int dest, void* recv,
                      std::size_t recv_bytes, int source, int tag) const;
  void isend_bytes(const void* data, std::size_t bytes, int dest, int tag, Requests& r) const;
  void irecv_bytes(void* data, std::size_t bytes, int source, int tag, Requests& r) const;

  template <class T>
  void broadcast(T& value, int root) const {
    static_assert(std::is_trivially_copyable_v<T>);
    broadcast_bytes(&value, sizeof(T), root);
  }
  template <class T>
  void broadcast(std::vector<T>& v, int root) const {
    static_assert(std::is_trivially_copyable_v<T>);
    std::int64_t n = static_cast<std::int64_t>(v.size());
    broadcast(n, root);
    v.resize(static_cast<std::size_t>(n));
    if (n > 0) broadcast_bytes(v.data(), v.size() * sizeof(T), root);
  }
  void broadcast(std::string& s, int root) const;
  template <class T>
  std::vector<T> allgather(const T& value) const {
    static_assert(std::is_trivially_copyable_v<T>);
    std::vector<T> out(static_cast<std::size_t>(size_));
    allgather_bytes(&value, sizeof(T), out.data());
    return out;
  }
  // Every rank's values, concatenated in rank order (not for the hot cycle: it allocates).
  template <class T>
  std::vector<T> allgatherv(std::span<const T> mine) const {
    std::vector<T> out;
    std::vector<std::int64_t> bytes;
    allgatherv(mine, out, bytes);
    return out;
  }
  // The same into `out`, with `bytes` for the ranks' sizes: both keep their capacity, so
  // once they have grown to their largest size the call allocates nothing.
  template <class T>
  void allgatherv(std::span<const T> mine, std::vector<T>& out,
                  std::vector<std::int64_t>& bytes) const {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto b = static_cast<std::int64_t>(mine.size_bytes());
    bytes.resize(static_cast<std::size_t>(size_));
    allgather_bytes(&b, sizeof b, bytes.data());
    std::int64_t total = 0;
    for (const std::int64_t k : bytes) total += k;
    out.resize(static_cast<std::size_t>(total) / sizeof(T));
    allgatherv_bytes(mine.data(), mine.size_bytes(), out.data(), bytes);
  }
  // One value to each rank, one value from each rank.
  template <class T>
  std::vector<T> alltoall(std::span<const T> send) const {
    static_assert(std::is_trivially_copyable_v<T>);
    std::vector<T> out(static_cast<std::size_t>(size_));
    alltoall_bytes(send.data(), sizeof(T), out.data());
    return out;
  }
  template <class T>
  void isend(std::span<const T> data, int dest, int tag, Requests& r) const {
    isend_bytes(data.data(), data.size_bytes(), dest, tag, r);
  }
  template <class T>
  void irecv(std::span<T> data, int source, int tag, Requests& r) const {
    irecv_bytes(data.data(), data.size_bytes(), source, tag, r);
  }

private:
  Comm(void* handle, bool owned);
  void* handle_ = nullptr; // MPI_Comm stored opaquely
  bool owned_ = false;
  int rank_ = 0;
  int size_ = 1;
  // allgatherv's counts and displacements in MPI's int, kept so that a call allocates
  // nothing once they have their size (QA round 29: the rigid bodies' gather of every
  // cycle allocated twice per call).
  mutable std::vector<int> gather_counts_, gather_displ_;
};

} // namespace anvil
