// SPDX-License-Identifier: MIT
// A fixed pool of threads that runs job(i) for i in [0, n), the caller's thread taking part; the
// indices are handed out one at a time, so a slow copy does not hold up a whole share.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <utility>
#include <thread>
#include <vector>

namespace turtlegas::learn::detail {

class WorkerPool {
 public:
  /// threads counts the caller: 1 runs every job on the caller's thread, starting none.
  explicit WorkerPool(std::size_t threads);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  std::size_t threads() const { return workers_.size() + 1; }
  /// Runs job(i) for every i in [0, n) and returns when all are done; rethrows the first
  /// exception a job threw (the other jobs still run).
  void run(std::size_t n, const std::function<void(std::size_t)>& job);

 private:
  void work();  // a worker's loop
  void drain(); // takes indices until none is left

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_;
  std::condition_variable finished_;
  std::uint64_t generation_ = 0;  // bumped for each run
  std::size_t busy_ = 0;          // workers still in the current run
  bool stopping_ = false;
  const std::function<void(std::size_t)>* job_ = nullptr;
  std::size_t n_ = 0;
  std::atomic<std::size_t> next_{0};
  std::exception_ptr error_;
};

}  // namespace turtlegas::learn::detail
