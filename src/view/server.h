// The viewer's HTTP server (emaki view, emaki lookdev, emaki.view() in Python): the page, the
// listings of the output folders and their files, on loopback unless told otherwise.
//
// Bounds: a fixed pool of worker threads, a short queue of accepted connections (when it is full
// the listener stops accepting until a worker frees a slot, so waiting connections stay in the
// kernel's backlog), read / write / keep-alive timeouts of a few seconds, request lines and
// headers capped by the HTTP layer (414 / 431), request paths by kMaxRequestPath, no bodies.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace emaki::view {

struct ServerOptions {
  std::string bind = "127.0.0.1";  // the address to listen on; never another unless asked
  int port = 0;                    // 0: one the system picks
  int threads = 4;                 // workers answering requests
  int queue = 16;                  // accepted connections waiting for a worker
  int timeout_seconds = 3;         // read, write and keep-alive
};

// Extra state a front end publishes under GET /api/status (lookdev's progress), as JSON.
using StatusJson = std::function<std::string()>;

class Server {
 public:
  // `folders`: the output folders, served as /files/0/..., /files/1/... Throws emaki::Error
  // naming the folder when one is not a readable folder.
  Server(std::vector<std::filesystem::path> folders, ServerOptions options, StatusJson status = {});
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Binds and starts answering on a thread of its own; returns the port. Throws emaki::Error
  // (field "port") when the address or port cannot be bound.
  int start();
  // Stops listening and joins the workers; safe to call twice.
  void stop();
  // Blocks until stop() (from another thread or a signal handler's flag poller).
  void wait();

  std::string url() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

}  // namespace emaki::view
