// `strata view`'s HTTP server: GET and HEAD only, its own routes only whatever the request line
// says, Host checked on loopback, and still serving after abuse. Requests are written byte by
// byte on a socket, so no client library tidies them first.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <thread>

#include "HttpServer.hpp"
#include "ViewTestMap.hpp"
#include "strata/core/Error.hpp"

namespace strata::view::test {
namespace {

// The status code of the answer to `request` (sent as is), 0 when the connection failed.
int Status(int port, const std::string& request, std::string* body = nullptr,
           std::string* head = nullptr) {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<uint16_t>(port));
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
        ::close(fd);
        return 0;
    }
    for (size_t sent = 0; sent < request.size();) {
        const ssize_t n = ::send(fd, request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
        if (n <= 0) break;
        sent += static_cast<size_t>(n);
    }
    // Read until the connection closes or the whole answer is in (a refused request may leave
    // the connection open until the server's read timeout).
    std::string answer;
    char buffer[65536];
    for (ssize_t n; (n = ::recv(fd, buffer, sizeof(buffer), 0)) > 0;) {
        answer.append(buffer, static_cast<size_t>(n));
        const size_t blank = answer.find("\r\n\r\n");
        const size_t length = answer.find("Content-Length: ");
        if (blank != std::string::npos && length != std::string::npos && length < blank &&
            answer.size() >= blank + 4 + std::stoul(answer.substr(length + 16))) {
            break;
        }
    }
    ::close(fd);
    const size_t end_of_head = std::min(answer.size(), answer.find("\r\n\r\n") + 4);
    if (body) *body = answer.substr(end_of_head);
    if (head) *head = answer.substr(0, end_of_head);
    return answer.rfind("HTTP/1.1 ", 0) == 0 ? std::stoi(answer.substr(9, 3)) : 0;
}

std::string Get(const std::string& target, int port, const std::string& host = "") {
    return "GET " + target +
           " HTTP/1.1\r\nHost: " + (host.empty() ? "127.0.0.1:" + std::to_string(port) : host) +
           "\r\nConnection: close\r\n\r\n";
}

class HttpServerTest : public ::testing::Test {
protected:
    static void SetUpTestSuite() { map_ = new TestMap(BuildTestMap("http")); }
    static void TearDownTestSuite() { delete map_; }

    void SetUp() override {
        auto service = std::make_shared<ViewService>(ViewSource::Open(map_->dir), LoadWebAssets());
        server_ = std::make_unique<HttpServer>(service, ServeOptions{"127.0.0.1", 0});
        thread_ = std::thread([this] { server_->Run(); });
        while (!server_->running()) std::this_thread::yield();
    }
    void TearDown() override {
        server_->Stop();
        thread_.join();
    }
    int port() const { return server_->port(); }

    static TestMap* map_;
    std::unique_ptr<HttpServer> server_;
    std::thread thread_;
};
TestMap* HttpServerTest::map_ = nullptr;

TEST_F(HttpServerTest, ServesThePageAndTheManifestOnLoopback) {
    std::string body;
    EXPECT_EQ(Status(port(), Get("/", port()), &body), 200);
    EXPECT_NE(body.find("<canvas"), std::string::npos);
    EXPECT_EQ(Status(port(), Get("/api/map", port()), &body), 200);
    EXPECT_NE(body.find("\"snapshots\""), std::string::npos);
    EXPECT_EQ(Status(port(), Get("/api/map", port(), "localhost:" + std::to_string(port()))), 200);
    EXPECT_EQ(Status(port(), "HEAD /app.js HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port()) +
                                 "\r\nConnection: close\r\n\r\n"),
              200);
}

TEST_F(HttpServerTest, ScriptsGoOutUncompressed) {
    // cpp-httplib would brotli-compress text/* at its slowest setting on every request.
    for (const std::string target : {"/three.min.js", "/app.js", "/api/map", "/"}) {
        const std::string request = "GET " + target +
                                    " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port()) +
                                    "\r\nAccept-Encoding: gzip, deflate, br\r\n"
                                    "Connection: close\r\n\r\n";
        std::string head;
        EXPECT_EQ(Status(port(), request, nullptr, &head), 200) << target;
        if (target != "/") {
            EXPECT_EQ(head.find("Content-Encoding"), std::string::npos) << target << head;
        }
    }
}

TEST_F(HttpServerTest, TraversalAttemptsGetA404AndTheServerKeepsServing) {
    for (const std::string target :
         {"/../catalog.sqlite", "/%2e%2e/catalog.sqlite", "/%2E%2E/%2E%2E/etc/passwd",
          "/..%2fcatalog.sqlite", "/api/tile/..%2F..%2Fcatalog.sqlite", "/tiles/0_0/v1.vdb",
          "/catalog.sqlite", "//etc/passwd", "/etc/passwd", "/%00", "/app.js%00.html",
          "/./app.js/..", "/index.html/../../catalog.sqlite", "/writer.lock"}) {
        std::string body;
        const int status = Status(port(), Get(target, port()), &body);
        EXPECT_TRUE(status == 404 || status == 400) << target << " -> " << status;
        EXPECT_EQ(body.find("SQLite format"), std::string::npos) << target;
        EXPECT_EQ(body.find("root:"), std::string::npos) << target;
    }
    // An absolute-form target and a very long one.
    EXPECT_EQ(Status(port(), Get("http://127.0.0.1/etc/passwd", port())), 404);
    const int long_status = Status(port(), Get("/" + std::string(9000, 'a'), port()));
    EXPECT_GE(long_status, 400);
    EXPECT_LT(long_status, 500);
    EXPECT_EQ(Status(port(), Get("/api/map", port())), 200);
}

TEST_F(HttpServerTest, OnlyGetAndHeadAreAnsweredAndTheMapIsNotTouched) {
    const auto before = std::filesystem::last_write_time(map_->dir / "catalog.sqlite");
    for (const std::string method : {"POST", "PUT", "DELETE", "PATCH", "OPTIONS"}) {
        const std::string request =
            method + " /api/map HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port()) +
            "\r\nContent-Length: 2\r\nConnection: close\r\n\r\n{}";
        EXPECT_EQ(Status(port(), request), 405) << method;
    }
    EXPECT_EQ(std::filesystem::last_write_time(map_->dir / "catalog.sqlite"), before);
}

TEST_F(HttpServerTest, AnotherHostNameIsRefusedOnLoopback) {
    // A page of evil.example that rebinds its name to 127.0.0.1 sends its own Host.
    EXPECT_EQ(Status(port(), Get("/api/map", port(), "evil.example:" + std::to_string(port()))),
              403);
    EXPECT_EQ(Status(port(), Get("/api/map", port(), "127.0.0.1:1")), 403);
}

TEST(HttpServer, RefusesBadOptionsAndAPortInUse) {
    const TestMap map = BuildTestMap("http_options");
    auto service = std::make_shared<ViewService>(ViewSource::Open(map.dir), LoadWebAssets());
    EXPECT_THROW(HttpServer(service, ServeOptions{"127.0.0.1", 70000}), InvalidArgumentError);
    EXPECT_THROW(HttpServer(service, ServeOptions{"", 0}), InvalidArgumentError);
    EXPECT_THROW(HttpServer(service, ServeOptions{"203.0.113.7", 0}), IoError);  // not ours
    HttpServer first(service, ServeOptions{"127.0.0.1", 0});
    EXPECT_THROW(HttpServer(service, ServeOptions{"127.0.0.1", first.port()}), IoError);
}

}  // namespace
}  // namespace strata::view::test
