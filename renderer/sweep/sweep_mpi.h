// MPI for sweeps, decided at run time: when the process was started by mpirun/srun (OpenMPI's
// OMPI_COMM_WORLD_SIZE, or PMI_SIZE / PMIX_RANK) MPI is initialised and the design points are
// spread over the ranks; otherwise nothing MPI is touched, so the plain command needs no mpirun.
// Only the main thread calls MPI (TBB workers never do). Messages to rank 0:
//   kResult  one finished point, its result JSON as text (so no shared filesystem is needed)
//   kDone    the rank has no more points (payload: how many results it sent)
//   kError   the rank failed (payload: the message); rank 0 stops waiting for it
#pragma once
#include <string>
#include <vector>

namespace ofl {

class MpiSession {
 public:
  enum Tag { kResult = 1, kDone = 2, kError = 3, kTodo = 4 };
  struct Message {
    int source = 0;
    int tag = 0;
    std::string payload;
  };

  // Initialises MPI when launched under an MPI launcher with more than one process.
  MpiSession();
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

  static bool launched_by_mpi();  // launcher environment with a world size > 1
  bool active() const { return active_; }
  int rank() const { return rank_; }
  int size() const { return size_; }

  // Rank 0's string to every rank.
  void broadcast(std::string& s);
  // Non-blocking send to rank 0; the buffer is kept until wait_sends().
  void send(int tag, const std::string& payload);
  void wait_sends();
  // Rank 0: the next message if one is waiting (block = wait for one).
  bool receive(Message* m, bool block);
  // Ends every rank at once (after an error that would leave the others waiting).
  [[noreturn]] void abort(int code);

 private:
  bool active_ = false;
  int rank_ = 0, size_ = 1;
  struct Pending;
  std::vector<Pending*> pending_;
};

}  // namespace ofl
