// `emaki view OUTPUT [OUTPUT_B]`: the output folders of shots on a local page (src/view/):
// a frame player, the layers, an A/B wipe, the contact sheet and the manifests.
#include <signal.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <string>
#include <vector>

#include "apps/emaki/commands.h"
#include "apps/emaki/staging_options.h"
#include "view/server.h"

namespace emaki::app {

// Serves until SIGINT or SIGTERM. The signals are blocked before the server's threads start
// (they inherit the mask), so the one sigwait() here takes them and the server stops cleanly.
int serve_until_signal(view::Server& server) {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  server.start();
  std::printf("%s\n", server.url().c_str());
  std::fflush(stdout);
  int signal = 0;
  sigwait(&set, &signal);
  server.stop();
  return 0;
}

void add_server_options(CLI::App& app, view::ServerOptions& o) {
  app.add_option("--port", o.port, "the port (default: one the system picks; the URL is printed)");
  app.add_option("--bind", o.bind,
                 "the address to listen on (default 127.0.0.1: this machine only)");
}

int run_view(const Args& args) {
  CLI::App app{
      "Serves a page showing a shot's output folder (and a second one, to compare) on this "
      "machine: frames, layers, an A/B wipe, the contact sheet and the manifests; frames appear "
      "as a run writes them. Prints the page's URL; Ctrl-C stops.",
      "emaki view"};
  std::vector<std::string> folders;
  view::ServerOptions o;
  app.add_option("outputs", folders, "OUTPUT [OUTPUT_B]: a shot's output folder(s)")
      ->required()
      ->expected(1, 2);
  add_server_options(app, o);
  if (parse_cli(app, args)) return 0;
  view::Server server({folders.begin(), folders.end()}, o);
  return serve_until_signal(server);
}

}  // namespace emaki::app
