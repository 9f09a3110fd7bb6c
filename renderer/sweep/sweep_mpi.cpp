#include "renderer/sweep/sweep_mpi.h"

#include <cstdlib>
#include <stdexcept>

#ifdef OFL_HAVE_MPI
#include <mpi.h>
#endif

namespace ofl {

struct MpiSession::Pending {
  std::string buffer;
#ifdef OFL_HAVE_MPI
  MPI_Request request;
#endif
};

bool MpiSession::launched_by_mpi() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MPI_LOCALNRANKS"}) {
    const char* s = std::getenv(v);
    if (s && std::atoi(s) > 1) return true;
  }
  return false;
}

MpiSession::MpiSession() {
  if (!launched_by_mpi()) return;
#ifdef OFL_HAVE_MPI
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  active_ = size_ > 1;
#else
  throw std::runtime_error("started under mpirun, but this oralfluor was built without MPI (install libopenmpi-dev and rebuild)");
#endif
}

MpiSession::~MpiSession() {
#ifdef OFL_HAVE_MPI
  if (!launched_by_mpi()) return;
  wait_sends();
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized) MPI_Finalize();
#endif
}

void MpiSession::broadcast(std::string& s) {
#ifdef OFL_HAVE_MPI
  if (!active_) return;
  long long n = static_cast<long long>(s.size());
  MPI_Bcast(&n, 1, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
  s.resize(size_t(n));
  if (n > 0) MPI_Bcast(s.data(), int(n), MPI_CHAR, 0, MPI_COMM_WORLD);
#else
  (void)s;
#endif
}

void MpiSession::send(int tag, const std::string& payload) {
#ifdef OFL_HAVE_MPI
  if (!active_) return;
  auto* p = new Pending;
  p->buffer = payload;
  MPI_Isend(p->buffer.data(), int(p->buffer.size()), MPI_CHAR, 0, tag, MPI_COMM_WORLD, &p->request);
  pending_.push_back(p);
#else
  (void)tag;
  (void)payload;
#endif
}

void MpiSession::wait_sends() {
#ifdef OFL_HAVE_MPI
  for (auto* p : pending_) {
    MPI_Wait(&p->request, MPI_STATUS_IGNORE);
    delete p;
  }
#endif
  pending_.clear();
}

bool MpiSession::receive(Message* m, bool block) {
#ifdef OFL_HAVE_MPI
  if (!active_) return false;
  MPI_Status st;
  int flag = 0;
  if (block) {
    MPI_Probe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &st);
    flag = 1;
  } else {
    MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &st);
  }
  if (!flag) return false;
  int count = 0;
  MPI_Get_count(&st, MPI_CHAR, &count);
  m->source = st.MPI_SOURCE;
  m->tag = st.MPI_TAG;
  m->payload.assign(size_t(count), '\0');
  MPI_Recv(m->payload.data(), count, MPI_CHAR, st.MPI_SOURCE, st.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return true;
#else
  (void)m;
  (void)block;
  return false;
#endif
}

void MpiSession::abort(int code) {
#ifdef OFL_HAVE_MPI
  if (active_) MPI_Abort(MPI_COMM_WORLD, code);
#endif
  std::exit(code);
}

}  // namespace ofl
