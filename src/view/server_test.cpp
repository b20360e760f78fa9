// The viewer's server under hostile requests, in-process on loopback: traversal (plain and
// percent-encoded), absolute paths, symlinks out, long URLs, a foreign Host, idle and many
// parallel connections. Each is refused or answered, and the server keeps answering.
#include "view/server.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <fstream>
#include <thread>

#include "core/error.h"

namespace emaki::view {
namespace {

namespace fs = std::filesystem;

int connect_to(int port) {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(uint16_t(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(s, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    ::close(s);
    return -1;
  }
  timeval tv{30, 0};
  ::setsockopt(s, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  return s;
}

// The status code of one raw request (the target sent byte for byte, no client-side
// normalisation), and its body; 0 when the server closed without an answer.
std::pair<int, std::string> raw_get(int port, const std::string& target,
                                    const std::string& host = "") {
  const int s = connect_to(port);
  if (s < 0) return {-1, ""};
  const std::string h = host.empty() ? "127.0.0.1:" + std::to_string(port) : host;
  const std::string request =
      "GET " + target + " HTTP/1.1\r\nHost: " + h + "\r\nConnection: close\r\n\r\n";
  for (std::size_t sent = 0; sent < request.size();) {
    const ssize_t n = ::send(s, request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) break;
    sent += std::size_t(n);
  }
  std::string reply;
  char buf[4096];
  for (ssize_t n; (n = ::recv(s, buf, sizeof buf, 0)) > 0;) reply.append(buf, std::size_t(n));
  ::close(s);
  if (reply.rfind("HTTP/1.1 ", 0) != 0) return {0, reply};
  const std::size_t body = reply.find("\r\n\r\n");
  return {std::stoi(reply.substr(9, 3)), body == std::string::npos ? "" : reply.substr(body + 4)};
}

class ViewServer : public ::testing::Test {
 protected:
  void SetUp() override {
    base = fs::temp_directory_path() / ("emaki_view_server_" + std::to_string(::getpid()));
    fs::remove_all(base);
    root = base / "out";
    fs::create_directories(root / "composite");
    fs::create_directories(root / "layers" / "base");
    std::ofstream(root / "composite" / "frame_0000.png") << "frame0";
    std::ofstream(root / "composite" / "frame_0001.png") << "frame1";
    std::ofstream(root / "layers" / "base" / "base_0000.png") << "base0";
    std::ofstream(root / "layers" / "base" / ".emaki-manifest") << "size = 4x4\n";
    std::ofstream(root / ".emaki.lock") << "lock";
    std::ofstream(base / "secret.txt") << "SECRET";
    fs::create_symlink(base / "secret.txt", root / "composite" / "frame_0002.png");
    server = std::make_unique<Server>(std::vector<fs::path>{root}, ServerOptions{});
    port = server->start();
  }
  void TearDown() override {
    server.reset();
    fs::remove_all(base);
  }
  fs::path base, root;
  std::unique_ptr<Server> server;
  int port = 0;
};

TEST_F(ViewServer, ServesThePageTheListingAndAFrame) {
  EXPECT_EQ(raw_get(port, "/").first, 200);
  EXPECT_EQ(raw_get(port, "/view.js").first, 200);
  const auto listing = raw_get(port, "/api/outputs");
  EXPECT_EQ(listing.first, 200);
  EXPECT_NE(listing.second.find("\"composite\""), std::string::npos) << listing.second;
  EXPECT_NE(listing.second.find("\"layers/base\""), std::string::npos) << listing.second;
  EXPECT_NE(listing.second.find("size = 4x4"), std::string::npos) << listing.second;
  EXPECT_EQ(listing.second.find("SECRET"), std::string::npos);
  EXPECT_EQ(raw_get(port, "/files/0/composite/frame_0001.png"),
            std::make_pair(200, std::string("frame1")));
  EXPECT_EQ(raw_get(port, "/files/0/composite/frame_0001.png?t=5").first, 200);
}

TEST_F(ViewServer, StreamsALargeFileWhole) {
  std::string big(300 * 1024 + 7, '\0');
  for (std::size_t i = 0; i < big.size(); ++i) big[i] = char(i * 7 % 251);
  std::ofstream(root / "contact_sheet.png", std::ios::binary) << big;
  EXPECT_EQ(raw_get(port, "/files/0/contact_sheet.png"), std::make_pair(200, big));
}

TEST_F(ViewServer, RefusesTraversalPlainAndEncoded) {
  for (const char* target :
       {"/files/0/../secret.txt", "/files/0/composite/../../secret.txt",
        "/files/0/%2e%2e/secret.txt", "/files/0/%2E%2E/secret.txt", "/files/0/..%2fsecret.txt",
        "/files/0/%2e%2e%2fsecret.txt", "/files/0/composite/%2e%2e/%2e%2e/secret.txt",
        "/files/0/%252e%252e/secret.txt", "/files/0/..%5csecret.txt",
        "/files/0/composite/frame_0000.png%00.txt", "/files/1/composite/frame_0000.png",
        "/files/0/.emaki.lock", "/files/0/layers/base/.emaki-manifest"}) {
    const auto r = raw_get(port, target);
    EXPECT_TRUE(r.first >= 400 && r.first < 500) << target << ": " << r.first;
    EXPECT_EQ(r.second.find("SECRET"), std::string::npos) << target;
  }
}

TEST_F(ViewServer, RefusesAbsolutePathsAndSymlinksOut) {
  for (const std::string& target :
       std::vector<std::string>{"/files/0//etc/passwd", "/files/0/%2fetc%2fpasswd",
                                "/files/0/" + base.string() + "/secret.txt", "//etc/passwd",
                                "/files/0/composite/frame_0002.png"}) {
    const auto r = raw_get(port, target);
    EXPECT_TRUE(r.first >= 400 && r.first < 500) << target << ": " << r.first;
    EXPECT_EQ(r.second.find("SECRET"), std::string::npos) << target;
    EXPECT_EQ(r.second.find("root:"), std::string::npos) << target;
  }
}

TEST_F(ViewServer, RefusesLongUrlsAndForeignHosts) {
  const std::string long_path = "/files/0/" + std::string(2000, 'a') + ".png";
  EXPECT_EQ(raw_get(port, long_path).first, 414);
  const auto huge = raw_get(port, "/files/0/" + std::string(100000, 'a'));
  EXPECT_TRUE(huge.first == 0 || (huge.first >= 400 && huge.first < 500)) << huge.first;
  EXPECT_EQ(raw_get(port, "/", "evil.example:" + std::to_string(port)).first, 403);
  EXPECT_EQ(raw_get(port, "/", "localhost:" + std::to_string(port)).first, 200);
  EXPECT_EQ(raw_get(port, "/api/outputs").first, 200);
}

TEST_F(ViewServer, ManyParallelConnectionsAreAllAnswered) {
  std::atomic<int> ok{0};
  std::vector<std::thread> clients;
  for (int i = 0; i < 48; ++i)
    clients.emplace_back([&] {
      for (int k = 0; k < 4; ++k)
        if (raw_get(port, "/files/0/composite/frame_0000.png").first == 200) ++ok;
    });
  for (auto& t : clients) t.join();
  EXPECT_EQ(ok.load(), 48 * 4);
  EXPECT_EQ(raw_get(port, "/").first, 200);
}

TEST_F(ViewServer, IdleConnectionsTimeOutAndTheServerAnswersAfterThem) {
  std::vector<int> idle;
  for (int i = 0; i < 12; ++i) idle.push_back(connect_to(port));
  // Each idle connection holds a worker for at most the read timeout (3 s): 12 over 4 workers
  // clear in about 9 s, well within the raw client's 30 s receive timeout.
  EXPECT_EQ(raw_get(port, "/files/0/composite/frame_0000.png").first, 200);
  for (const int s : idle) ::close(s);
}

TEST(ViewServerSetup, AMissingFolderOrABusyPortIsAnError) {
  EXPECT_THROW(Server({"/nonexistent/emaki_view"}, ServerOptions{}), Error);
  Server a({fs::temp_directory_path()}, ServerOptions{});
  const int port = a.start();
  ServerOptions busy;
  busy.port = port;
  Server b({fs::temp_directory_path()}, busy);
  EXPECT_THROW(b.start(), Error);
}

}  // namespace
}  // namespace emaki::view
