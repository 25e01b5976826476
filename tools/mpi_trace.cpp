// A record of every blocking MPI call of a run, for finding where the ranks wait: preload
// it (mpirun -x LD_PRELOAD=build/tools/libanvil_mpi_trace.so ...) and each rank writes,
// at MPI_Finalize, PREFIX.RANK.bin (PREFIX from ANVIL_MPI_TRACE, default mpi_trace): one
// record per call of the collectives, waits and receives anvil makes (and per MPI_Isend,
// with its size), through the PMPI profiling interface. tools/mpi_trace.py reads them.
// A profiling tool only: no part of anvil links it.
#include <mpi.h>

#include <dlfcn.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

namespace {

// Kinds of call (tools/mpi_trace.py has the same list).
enum Kind : std::int32_t { allreduce = 1, allgather, waitall, sendrecv, recv, alltoall, isend };

struct Record {
  double t0, t1;      // CLOCK_MONOTONIC, s: entry and return
  std::uint64_t site; // return address, as an offset in its object file
  std::int32_t kind;
  std::int32_t bytes; // MPI_Isend: the message's size; else 0
};
static_assert(sizeof(Record) == 32);

double now() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::vector<Record>& records() {
  static std::vector<Record> r = [] {
    std::vector<Record> v;
    v.reserve(1 << 22); // a 64 MiB start: a whole can crush on 2 ranks needs no growth
    return v;
  }();
  return r;
}

void add(double t0, void* site, Kind kind, int bytes = 0) {
  records().push_back({t0, now(), reinterpret_cast<std::uint64_t>(site), kind, bytes});
}

// Times call() (the PMPI function) as one record of `kind` made at `site` (the wrapper's
// return address: it must be taken in the wrapper itself).
template <class Call>
int timed(Kind kind, void* site, Call&& call) {
  const double t0 = now();
  const int rc = call();
  add(t0, site, kind);
  return rc;
}

} // namespace

extern "C" {

int MPI_Allreduce(const void* s, void* r, int n, MPI_Datatype t, MPI_Op op, MPI_Comm c) {
  return timed(allreduce, __builtin_return_address(0),
               [&] { return PMPI_Allreduce(s, r, n, t, op, c); });
}

int MPI_Allgather(const void* s, int sn, MPI_Datatype st, void* r, int rn, MPI_Datatype rt,
                  MPI_Comm c) {
  return timed(allgather, __builtin_return_address(0),
               [&] { return PMPI_Allgather(s, sn, st, r, rn, rt, c); });
}

int MPI_Alltoall(const void* s, int sn, MPI_Datatype st, void* r, int rn, MPI_Datatype rt,
                 MPI_Comm c) {
  return timed(alltoall, __builtin_return_address(0),
               [&] { return PMPI_Alltoall(s, sn, st, r, rn, rt, c); });
}

int MPI_Waitall(int n, MPI_Request* q, MPI_Status* st) {
  return timed(waitall, __builtin_return_address(0), [&] { return PMPI_Waitall(n, q, st); });
}

int MPI_Sendrecv(const void* s, int sn, MPI_Datatype st, int dest, int stag, void* r, int rn,
                 MPI_Datatype rt, int source, int rtag, MPI_Comm c, MPI_Status* status) {
  return timed(sendrecv, __builtin_return_address(0), [&] {
    return PMPI_Sendrecv(s, sn, st, dest, stag, r, rn, rt, source, rtag, c, status);
  });
}

int MPI_Recv(void* b, int n, MPI_Datatype t, int source, int tag, MPI_Comm c, MPI_Status* st) {
  return timed(recv, __builtin_return_address(0),
               [&] { return PMPI_Recv(b, n, t, source, tag, c, st); });
}

int MPI_Isend(const void* b, int n, MPI_Datatype t, int dest, int tag, MPI_Comm c, MPI_Request* q) {
  const double t0 = now();
  const int rc = PMPI_Isend(b, n, t, dest, tag, c, q);
  int size = 0;
  PMPI_Type_size(t, &size);
  add(t0, __builtin_return_address(0), isend, n * size);
  return rc;
}

int MPI_Finalize() {
  int rank = 0;
  PMPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const char* prefix = std::getenv("ANVIL_MPI_TRACE");
  const std::string path =
      std::string(prefix ? prefix : "mpi_trace") + "." + std::to_string(rank) + ".bin";
  auto& r = records();
  for (auto& x : r) {
    Dl_info info;
    if (dladdr(reinterpret_cast<void*>(x.site), &info) != 0)
      x.site -= reinterpret_cast<std::uint64_t>(info.dli_fbase);
  }
  if (std::FILE* f = std::fopen(path.c_str(), "wb")) {
    std::fwrite(r.data(), sizeof(Record), r.size(), f);
    std::fclose(f);
  } else {
    std::fprintf(stderr, "mpi_trace: cannot write %s\n", path.c_str());
  }
  return PMPI_Finalize();
}

} // extern "C"
