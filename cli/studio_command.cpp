// `rigc studio`: the interactive capture environment in the browser (studio/).
#include <fmt/format.h>
#include <pthread.h>
#include <signal.h>

#include <iostream>
#include <thread>

#include "assets/model_cache.h"
#include "cli/commands.h"
#include "cli/options.h"
#include "cli/verbs.h"
#include "io/allocator.h"
#include "studio/server.h"

namespace rigc::cli {
namespace {

// Blocks the stop signals in this thread (and the server's threads it starts) and returns them,
// so that one thread can wait for them and stop the server cleanly.
sigset_t block_stop_signals() {
  sigset_t signals;
  sigemptyset(&signals);
  for (const int s : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&signals, s);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  return signals;
}

}  // namespace

int run_studio_command(std::vector<std::string> args) {
  CLI::App app{
      "Open the interactive capture studio in a browser: move the camera, change the "
      "settings, capture, watch the coverage, save back into the scene file."};
  app.footer("\nExample:\n  rigc studio scenes/paper-turntable.yaml");
  std::string scene_path;
  studio::ServerOptions options;
  app.add_option("scene", scene_path, "scene file (.yaml)")->required();
  app.add_option("--host", options.host,
                 "address to listen on (default 127.0.0.1; another one lets others connect)");
  app.add_option("--port", options.port, "port (default: any free one)")
      ->check(CLI::Range(0, 65535));
  std::string run_folder;
  app.add_option("-o,--output", run_folder,
                 "run folder of the reference checks (default: out/<scene>/studio)");
  if (auto code = parse_options(app, args)) return *code;
  // Before any thread starts (the compiler's and the renderer's workers inherit the mask).
  const sigset_t signals = block_stop_signals();

  share_heap_arenas();  // before the workers start
  // Each camera move and setting is a compile of the scene: its mesh is loaded once.
  keep_loaded_models(true);
  std::string error;
  const auto session = studio::Session::open(scene_path, &error, run_folder);
  if (!session) {
    std::cerr << error;
    return kExitUserError;
  }
  if (options.host != "127.0.0.1" && options.host != "localhost" && options.host != "::1") {
    std::cerr << fmt::format(
        "rigc: warning: listening on {}: anyone who can reach it and has the address with its "
        "token can change and save {}\n",
        options.host, scene_path);
  }
  studio::StudioServer server(*session, options);
  if (server.bind(&error) < 0) {
    std::cerr << "rigc: error: " << error << '\n';
    return kExitUserError;
  }
  std::cout << fmt::format("rigc studio: {} at {}\n(Ctrl-C stops it)\n", scene_path, server.url())
            << std::flush;
  std::thread stopper([&] {
    int signal_number = 0;
    sigwait(&signals, &signal_number);
    server.stop();
  });
  const bool served = server.run();
  // run() returned: a signal stopped it, or it failed and the waiter still waits for one.
  if (!served) pthread_kill(stopper.native_handle(), SIGTERM);
  stopper.join();
  std::cout << "rigc studio: stopped\n";
  return served ? kExitOk : kExitInternalError;
}

}  // namespace rigc::cli
