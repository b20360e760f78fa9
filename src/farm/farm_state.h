// What `emaki farm` reads back from a shot's farm folder (jobs.tsv, chunk, a task's exit code and
// log) and from squeue. Anything there may be stale, copied or planted: a file is read only when
// it is a regular file within a size cap (a FIFO would hang the reader, /dev/zero would fill
// memory), and text that is not what emaki writes is an error naming the file and line.
#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <string_view>

namespace emaki::farm {

constexpr std::size_t kMaxJobsFileBytes = std::size_t(64) << 20;  // jobs.tsv: ~1M task records
constexpr std::size_t kMaxSmallFileBytes = 4096;                  // farm/chunk, status/TASK.exit
constexpr std::size_t kLogTailBytes = std::size_t(64) << 10;      // the part of a log status reads

// The whole of `path`: nullopt when nothing is there. Throws Error(path) when it is not a regular
// file (a FIFO, a device, a folder; a symlink counts as what it points to) or holds more than
// `cap` bytes. Never blocks on a FIFO.
std::optional<std::string> read_state_file(const std::string& path, std::size_t cap);

// The last `tail` bytes of the regular file `path` (a log, however long): nullopt when nothing
// is there. Throws Error(path) when it is not a regular file.
std::optional<std::string> read_file_tail(const std::string& path, std::size_t tail);

// jobs.tsv's records, "TASK \t JOBID \t INDEX" a line: task -> "JOBID_INDEX", a later line
// winning. Throws Error(subject) naming the line when one is not such a record (the job id and
// index decimal, the task id non-empty and free of control characters).
std::map<std::string, std::string> parse_jobs(std::string_view text, const std::string& subject);

// One jobs.tsv record as append_jobs writes it.
std::string job_record(const std::string& task, const std::string& job, std::size_t index);

// farm/chunk's text: one decimal number in [1, kMaxFrameCount] and a newline. Throws
// Error(subject) otherwise.
int parse_chunk(std::string_view text, const std::string& subject);

// farm/threads' text: one decimal number in [1, 1024] and a newline. Throws Error(subject)
// otherwise.
int parse_threads(std::string_view text, const std::string& subject);

// A status/TASK.exit file's text: a decimal exit code in [0, 255] and a newline; nullopt
// otherwise (a half-written or foreign file is no exit code).
std::optional<int> parse_exit_code(std::string_view text);

// One job array element in squeue's output.
struct QueuedJob {
  std::string state, reason, name;
};

// squeue -h -r -o '%i|%T|%r|%j': "JOBID_INDEX" (a job outside an array as "JOBID_0") -> its
// state, reason and name. Lines that are not such records are left out.
std::map<std::string, QueuedJob> parse_queue(std::string_view text);

}  // namespace emaki::farm
