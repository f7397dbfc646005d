// The campaign over MPI ranks (docs/theory.md §11.6): dynamic load balancing with every rank
// working, rank 0 included.
//
// Rank 0 holds the schedule (campaign_schedule.h) and the store. A coordinator thread on rank 0
// answers the other ranks: a rank that is free sends what it finished (the case's result row, or
// that a truth is written) and gets its next task, "wait" or "done"; rank 0 stores the result
// atomically and prints the progress line. Rank 0's main thread takes tasks from the same
// schedule between the answers (MPI_THREAD_SERIALIZED: only the coordinator calls MPI while it
// runs). Waiting sides poll with short sleeps rather than blocking in MPI, so an idle rank does
// not spin a core away from a working one. The report is written by rank 0 from the stored cases
// only: the same bytes for any number of ranks.
#include "campaign_mpi.h"

#include <mpi.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <optional>
#include <thread>

#include "scoleid/io/error.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/validation.h"

namespace scoleid::crosscheck {

using nlohmann::json;

namespace {

constexpr int kTagRequest = 1, kTagTask = 2;
constexpr int kDone = -1, kWait = -2;

void nap(int ms) { std::this_thread::sleep_for(std::chrono::milliseconds(ms)); }

[[noreturn]] void abort_all(int code) {
  std::fflush(stderr);
  MPI_Abort(MPI_COMM_WORLD, code);
  std::_Exit(code);
}

// Rank 0's shared state, behind one mutex.
struct Coordinator {
  const Campaign& c;
  const CampaignStore& store;
  const CampaignRunOptions& opt;
  CampaignSchedule sched;
  CampaignRunSummary sum;
  std::mutex m;
  std::chrono::steady_clock::time_point t0;
  // Set by rank 0's main thread when its own work fails: the coordinator thread, the only one in
  // MPI while it runs, then aborts the job.
  std::atomic<int> abort_code{0};

  // Records a finished task of `rank` (lock held).
  void record(const CampaignTask& t, const json& r, double sec, int rank) {
    sum.ranks[static_cast<std::size_t>(rank)].busy_seconds += sec;
    ++sum.ranks[static_cast<std::size_t>(rank)].tasks;
    if (t.kind == CampaignTask::Kind::Case) {
      store.store(t.index, r);
      ++sum.ran;
      sum.failed += r.contains("failed") ? 1 : 0;
      sum.tasks.push_back({{"task", c.cases[t.index].id}, {"rank", rank}, {"seconds", sec}});
      if (opt.progress)
        std::fprintf(stderr, "scole-crosscheck campaign: [%zu/%zu] %s (rank %d, %.1f s)\n", sum.done_before + sum.ran, sum.cases,
                     case_line(c, t.index, r).c_str(), rank, sec);
    } else {
      sum.tasks.push_back({{"task", "truth " + c.points[t.index].id}, {"rank", rank}, {"seconds", sec}});
      if (opt.progress)
        std::fprintf(stderr, "scole-crosscheck campaign: truth of %s (%s): %s (rank %d, %.1f s)\n", c.points[t.index].id.c_str(),
                     c.points[t.index].label.c_str(),
                     r.contains("failed") ? ("FAILED: " + r["failed"].get<std::string>()).c_str() : "done", rank, sec);
    }
    sched.finished(t);
  }

  // Answers the other ranks until each has been told "done"; an interrupt (or rank 0's own work
  // failing) ends the job from here.
  void serve(int ranks) {
    int active = ranks - 1;
    while (active > 0) {
      int flag = 0;
      MPI_Status st;
      MPI_Iprobe(MPI_ANY_SOURCE, kTagRequest, MPI_COMM_WORLD, &flag, &st);
      if (!flag) {
        if (abort_code.load() != 0) abort_all(abort_code.load());
        io::check_interrupt();
        nap(2);
        continue;
      }
      int len = 0;
      MPI_Get_count(&st, MPI_CHAR, &len);
      std::string buf(static_cast<std::size_t>(len), '\0');
      MPI_Recv(buf.data(), len, MPI_CHAR, st.MPI_SOURCE, kTagRequest, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      int reply[2] = {kDone, 0};
      {
        std::lock_guard<std::mutex> lock(m);
        const json msg = json::parse(buf);
        if (msg.contains("kind")) {
          const CampaignTask t{msg["kind"].get<int>() == 0 ? CampaignTask::Kind::Truth : CampaignTask::Kind::Case,
                               msg["index"].get<std::size_t>()};
          record(t, msg["result"], msg["seconds"].get<double>(), st.MPI_SOURCE);
        }
        CampaignTask t;
        const auto n = sched.next(t);
        if (n == CampaignSchedule::Next::Run) {
          if (opt.progress && t.kind == CampaignTask::Kind::Truth) truth_started(c, t.index, st.MPI_SOURCE);
          reply[0] = t.kind == CampaignTask::Kind::Truth ? 0 : 1;
          reply[1] = static_cast<int>(t.index);
        } else if (n == CampaignSchedule::Next::Wait) {
          reply[0] = kWait;
        } else {
          --active;
        }
      }
      MPI_Send(reply, 2, MPI_INT, st.MPI_SOURCE, kTagTask, MPI_COMM_WORLD);
    }
  }

  // Rank 0's own share of the work.
  void work(int kill_after, int sweep_threads) {
    int finished = 0;
    for (;;) {
      CampaignTask t;
      CampaignSchedule::Next n;
      {
        std::lock_guard<std::mutex> lock(m);
        n = sched.next(t);
      }
      if (n == CampaignSchedule::Next::Done) return;
      if (n == CampaignSchedule::Next::Wait) {
        io::check_interrupt();
        nap(50);
        continue;
      }
      const bool die = kill_after >= 0 && t.kind == CampaignTask::Kind::Case && finished == kill_after;
      if (opt.progress && t.kind == CampaignTask::Kind::Truth) {
        std::lock_guard<std::mutex> lock(m);
        truth_started(c, t.index, 0);
      }
      const auto a = std::chrono::steady_clock::now();
      const json r = execute_task(c, store, t, die, sweep_threads);
      const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count();
      std::lock_guard<std::mutex> lock(m);
      record(t, r, sec, 0);
      finished += t.kind == CampaignTask::Kind::Case ? 1 : 0;
    }
  }
};

// A rank other than 0: ask, run, report, until told "done".
void worker(const Campaign& c, const CampaignStore& store, int kill_after, int sweep_threads) {
  json msg = json::object();
  int finished = 0;
  for (;;) {
    const std::string out = msg.dump();
    MPI_Send(out.data(), static_cast<int>(out.size()), MPI_CHAR, 0, kTagRequest, MPI_COMM_WORLD);
    int reply[2];
    MPI_Request req;
    MPI_Irecv(reply, 2, MPI_INT, 0, kTagTask, MPI_COMM_WORLD, &req);
    for (int flag = 0;;) {
      MPI_Test(&req, &flag, MPI_STATUS_IGNORE);
      if (flag) break;
      io::check_interrupt();
      nap(1);
    }
    if (reply[0] == kDone) return;
    if (reply[0] == kWait) {
      msg = json::object();
      nap(50);
      continue;
    }
    const CampaignTask t{reply[0] == 0 ? CampaignTask::Kind::Truth : CampaignTask::Kind::Case, static_cast<std::size_t>(reply[1])};
    const bool die = kill_after >= 0 && t.kind == CampaignTask::Kind::Case && finished == kill_after;
    const auto a = std::chrono::steady_clock::now();
    const json r = execute_task(c, store, t, die, sweep_threads);
    const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count();
    finished += t.kind == CampaignTask::Kind::Case ? 1 : 0;
    msg = json{{"kind", reply[0]}, {"index", reply[1]}, {"result", r}, {"seconds", sec}};
  }
}

}  // namespace

int run_campaign_mpi(const std::string& file, CampaignRunOptions opt) {
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  // Several ranks share the machine's cores: each identifies on one thread per sweep (the same
  // numbers as two; ObjectiveOptions::sweep_threads).
  const int sweep_threads = size > 1 ? 1 : 0;
  int code = 0;
  try {
    // Every rank reads the file (the same checks, the same cases); rank 0 alone speaks.
    std::optional<Campaign> c;
    std::string err;
    try {
      c = load_campaign(file);
      if (opt.out.empty()) opt.out = "run/campaign/" + c->name;
    } catch (const io::InputError& e) {
      err = e.what();
    }
    int ok = err.empty() ? 1 : 0, all_ok = 0;
    MPI_Allreduce(&ok, &all_ok, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (!all_ok) {
      if (rank == 0) std::fprintf(stderr, "scole-crosscheck: %s\n", io::one_line(err.empty() ? "campaign file '" + file + "': unreadable on another rank" : err).c_str());
      MPI_Finalize();
      return 2;
    }
    // Rank 0 creates the store first; the others then see it (a shared file system).
    std::optional<CampaignStore> store;
    err.clear();
    if (rank == 0) {
      try {
        store.emplace(*c, opt.out, true);
      } catch (const io::InputError& e) {
        err = e.what();
      }
    }
    ok = err.empty() ? 1 : 0;
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (!ok) {
      if (rank == 0) std::fprintf(stderr, "scole-crosscheck: %s\n", io::one_line(err).c_str());
      MPI_Finalize();
      return 2;
    }
    if (rank != 0) store.emplace(*c, opt.out);
    const int kill_rank = opt.kill_rank >= 0 ? opt.kill_rank : size - 1;
    const int kill_after = rank == kill_rank ? opt.kill_after : -1;
    MPI_Barrier(MPI_COMM_WORLD);
    if (rank == 0) {
      Coordinator co{*c, *store, opt, make_schedule(*c, *store), {}, {}, std::chrono::steady_clock::now()};
      co.sum.cases = co.sched.cases();
      co.sum.done_before = co.sched.cases_done_before();
      co.sum.ranks.resize(static_cast<std::size_t>(size));
      if (opt.progress)
        std::fprintf(stderr, "scole-crosscheck campaign: %s: %zu cases on %d ranks%s\n", c->name.c_str(), co.sum.cases, size,
                     co.sum.done_before ? (", " + std::to_string(co.sum.done_before) + " already stored, not run again").c_str() : "");
      if (size > 1 && provided >= MPI_THREAD_SERIALIZED) {
        // The coordinator thread is the only one in MPI while it runs: what ends the job on this
        // rank (an interrupt, a failure of either thread) ends it from there.
        std::thread serve([&] {
          try {
            co.serve(size);
          } catch (const io::Interrupted& e) {
            std::fprintf(stderr, "\nscole-crosscheck: rank 0: %s\n", interrupted_line(e).c_str());
            abort_all(e.exit_code());
          } catch (const std::exception& e) {
            std::fprintf(stderr, "scole-crosscheck: rank 0: run failed: %s\n", io::one_line(e.what()).c_str());
            abort_all(1);
          }
        });
        try {
          co.work(kill_after, sweep_threads);
        } catch (const io::Interrupted& e) {
          std::fprintf(stderr, "\nscole-crosscheck: rank 0: %s\n", interrupted_line(e).c_str());
          co.abort_code = e.exit_code();
        } catch (const std::exception& e) {
          std::fprintf(stderr, "scole-crosscheck: rank 0: run failed: %s\n", io::one_line(e.what()).c_str());
          co.abort_code = 1;
        }
        serve.join();
        if (co.abort_code.load() != 0) abort_all(co.abort_code.load());  // the coordinator had finished
      } else if (size > 1) {
        co.serve(size);  // no threads in this MPI: rank 0 only coordinates
      } else {
        co.work(kill_after, sweep_threads);
      }
      co.sum.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - co.t0).count();
      code = finish_campaign(*c, *store, co.sum, opt);
    } else {
      worker(*c, *store, kill_after, sweep_threads);
    }
    MPI_Bcast(&code, 1, MPI_INT, 0, MPI_COMM_WORLD);
  } catch (const io::Interrupted& e) {
    std::fprintf(stderr, "\nscole-crosscheck: rank %d: %s\n", rank, interrupted_line(e).c_str());
    abort_all(e.exit_code());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scole-crosscheck: rank %d: run failed: %s\n", rank, io::one_line(e.what()).c_str());
    abort_all(1);
  }
  MPI_Finalize();
  return code;
}

}  // namespace scoleid::crosscheck
