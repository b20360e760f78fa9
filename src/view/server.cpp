#include "view/server.h"

#include <fmt/format.h>
#include <httplib.h>

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <fstream>
#include <memory>
#include <mutex>
#include <thread>

#include "core/error.h"
#include "core/limits.h"
#include "view/confine.h"
#include "view/listing.h"
#include "view/page_files.h"

namespace emaki::view {

namespace fs = std::filesystem;

namespace {

// The largest file served (streamed): a preview.mp4 of a long shot stays below it.
constexpr std::uintmax_t kMaxServedFileBytes = std::uintmax_t(1) << 30;

// httplib's task queue with a bound: `workers` threads, at most `limit` connections waiting.
// When the queue is full, enqueue() (called by the listening thread) waits, so no further
// connection is accepted until a worker frees a slot.
class BoundedPool : public httplib::TaskQueue {
 public:
  BoundedPool(int workers, int limit) : m_limit(std::size_t(limit)) {
    for (int i = 0; i < workers; ++i) m_threads.emplace_back([this] { work(); });
  }
  void enqueue(std::function<void()> fn) override {
    std::unique_lock lock(m_mutex);
    m_space.wait(lock, [&] { return m_jobs.size() < m_limit || m_shutdown; });
    m_jobs.push_back(std::move(fn));
    m_ready.notify_one();
  }
  void shutdown() override {
    {
      std::lock_guard lock(m_mutex);
      m_shutdown = true;
    }
    m_ready.notify_all();
    m_space.notify_all();
    for (auto& t : m_threads) t.join();
  }

 private:
  void work() {
    for (;;) {
      std::function<void()> fn;
      {
        std::unique_lock lock(m_mutex);
        m_ready.wait(lock, [&] { return !m_jobs.empty() || m_shutdown; });
        if (m_jobs.empty()) return;
        fn = std::move(m_jobs.front());
        m_jobs.pop_front();
        m_space.notify_one();
      }
      fn();
    }
  }
  std::size_t m_limit;
  std::mutex m_mutex;
  std::condition_variable m_ready, m_space;
  std::deque<std::function<void()>> m_jobs;
  std::vector<std::thread> m_threads;
  bool m_shutdown = false;
};

const char* content_type(const fs::path& p) {
  const std::string ext = p.extension().string();
  if (ext == ".png") return "image/png";
  if (ext == ".jpg" || ext == ".jpeg") return "image/jpeg";
  if (ext == ".mp4") return "video/mp4";
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".js") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  return "application/octet-stream";
}

bool is_loopback(const std::string& address) {
  return address == "127.0.0.1" || address == "::1" || address == "localhost";
}

}  // namespace

struct Server::Impl {
  std::vector<fs::path> folders;
  ServerOptions options;
  StatusJson status;
  httplib::Server http;
  std::thread listener;
  int port = 0;
  std::mutex mutex;
  std::condition_variable stopped_cv;
  bool stopped = false;

  // Loopback servers answer only requests addressed to loopback names: a page on another site
  // that points a DNS name at 127.0.0.1 (DNS rebinding) sends its own Host and is refused.
  bool host_allowed(const httplib::Request& req) const {
    if (!is_loopback(options.bind)) return true;
    const std::string host = req.get_header_value("Host");
    const std::string p = fmt::format(":{}", port);
    if (host.size() <= p.size() || !host.ends_with(p)) return false;
    const std::string name = host.substr(0, host.size() - p.size());
    return name == "127.0.0.1" || name == "localhost" || name == "[::1]";
  }

  void serve_file(const httplib::Request& req, httplib::Response& res) {
    const std::size_t index = std::size_t(req.matches[1].str()[0] - '0');
    const std::string relative = req.matches[2].str();
    if (index >= folders.size()) return void(res.status = 404);
    const auto file = confined_file(folders[index], relative);
    if (!file) return void(res.status = 404);
    std::error_code ec;
    const auto size = fs::file_size(*file, ec);
    if (ec || size > kMaxServedFileBytes) return void(res.status = 404);
    // Streamed in pieces of 64 KiB: a worker holds one piece, whatever the file's size.
    auto in = std::make_shared<std::ifstream>(*file, std::ios::binary);
    if (!*in) return void(res.status = 404);
    res.set_header("Cache-Control", "no-cache");
    res.set_content_provider(std::size_t(size), content_type(*file),
                             [in](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
                               char buf[64 * 1024];
                               in->seekg(std::streamoff(offset));
                               in->read(buf, std::streamsize(std::min(length, sizeof buf)));
                               const std::streamsize n = in->gcount();
                               return n > 0 && sink.write(buf, std::size_t(n));
                             });
  }

  void routes() {
    for (int i = 0; i < kPageFileCount; ++i) {
      const PageFile& f = kPageFiles[i];
      const std::string path =
          std::string("/") + (std::string(f.name) == "index.html" ? "" : f.name);
      http.Get(path, [&f](const httplib::Request&, httplib::Response& res) {
        res.set_content(reinterpret_cast<const char*>(f.data), f.size, content_type(f.name));
      });
    }
    http.Get("/api/outputs", [this](const httplib::Request&, httplib::Response& res) {
      std::vector<Listing> listings;
      for (const fs::path& f : folders) listings.push_back(scan_output(f));
      res.set_header("Cache-Control", "no-store");
      res.set_content(listing_json(listings), "application/json");
    });
    http.Get("/api/status", [this](const httplib::Request&, httplib::Response& res) {
      res.set_header("Cache-Control", "no-store");
      res.set_content(status ? status() : "{}", "application/json");
    });
    http.Get(R"(/files/([0-9])/(.+))",
             [this](const httplib::Request& req, httplib::Response& res) { serve_file(req, res); });
    http.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
      res.set_header("X-Content-Type-Options", "nosniff");
      res.set_header("Referrer-Policy", "no-referrer");
      if (req.path.size() > kMaxRequestPath + 16) {
        res.status = 414;
        return httplib::Server::HandlerResponse::Handled;
      }
      if (!host_allowed(req)) {
        res.status = 403;
        return httplib::Server::HandlerResponse::Handled;
      }
      return httplib::Server::HandlerResponse::Unhandled;
    });
  }
};

Server::Server(std::vector<fs::path> folders, ServerOptions options, StatusJson status)
    : m_impl(std::make_unique<Impl>()) {
  for (const fs::path& f : folders) {
    std::error_code ec;
    const fs::path real = fs::canonical(f, ec);
    if (ec || !fs::is_directory(real, ec))
      throw Error(echo_path(f.string()), "is not a folder emaki view can read");
    m_impl->folders.push_back(real);
  }
  if (m_impl->folders.empty() || m_impl->folders.size() > 10)
    throw Error("OUTPUT", "emaki view serves one to ten output folders");
  m_impl->options = std::move(options);
  m_impl->status = std::move(status);
  const ServerOptions& o = m_impl->options;
  httplib::Server& h = m_impl->http;
  h.new_task_queue = [o] { return new BoundedPool(o.threads, o.queue); };
  h.set_read_timeout(o.timeout_seconds, 0);
  h.set_write_timeout(o.timeout_seconds, 0);
  h.set_keep_alive_timeout(o.timeout_seconds);
  h.set_keep_alive_max_count(100);
  h.set_payload_max_length(0);
  // httplib's default also sets SO_REUSEPORT, which would let a second server share a port in
  // use instead of failing; SO_REUSEADDR alone keeps a restart from waiting for TIME_WAIT.
  h.set_socket_options([](int sock) {
    int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  m_impl->routes();
}

Server::~Server() {
  stop();
}

int Server::start() {
  Impl& m = *m_impl;
  const std::string& bind = m.options.bind;
  if (m.options.port == 0) {
    m.port = m.http.bind_to_any_port(bind);
    if (m.port <= 0) throw Error(Error::Field{"port"}, "cannot listen on " + echo(bind));
  } else {
    if (!m.http.bind_to_port(bind, m.options.port))
      throw Error(Error::Field{"port"}, "cannot listen on " + echo(bind) + ":" +
                                            std::to_string(m.options.port) +
                                            " (in use, or not this machine's)");
    m.port = m.options.port;
  }
  m.listener = std::thread([&m] {
    m.http.listen_after_bind();
    std::lock_guard lock(m.mutex);
    m.stopped = true;
    m.stopped_cv.notify_all();
  });
  // httplib's stop() does nothing until its loop runs: wait for it, so that stop() right after
  // start() cannot leave the listener running forever.
  while (!m.http.is_running()) {
    {
      std::lock_guard lock(m.mutex);
      if (m.stopped) throw Error(Error::Field{"port"}, "the server stopped as it started");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return m.port;
}

void Server::stop() {
  if (!m_impl) return;
  m_impl->http.stop();
  if (m_impl->listener.joinable()) m_impl->listener.join();
}

void Server::wait() {
  std::unique_lock lock(m_impl->mutex);
  m_impl->stopped_cv.wait(lock, [&] { return m_impl->stopped; });
}

std::string Server::url() const {
  const std::string& b = m_impl->options.bind;
  const std::string host = b.find(':') != std::string::npos ? "[" + b + "]" : b;
  return "http://" + host + ":" + std::to_string(m_impl->port) + "/";
}

}  // namespace emaki::view
