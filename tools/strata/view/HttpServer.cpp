#include "HttpServer.hpp"

#include <httplib.h>
#include <sys/socket.h>

#include <atomic>
#include <set>

#include "strata/core/Error.hpp"

namespace strata::view {
namespace {

bool IsLoopback(const std::string& address) {
    return address == "127.0.0.1" || address == "localhost" || address == "::1";
}

void Reject(httplib::Response& res, int status, const std::string& what) {
    res.status = status;
    res.set_content("{\"error\":\"" + what + "\"}", "application/json");
}

}  // namespace

void ServeOptions::Validate() const {
    if (port < 0 || port > 65535) throw InvalidArgumentError("--port must be in [0, 65535]");
    if (bind.empty()) throw InvalidArgumentError("--bind needs an address");
}

struct HttpServer::Impl {
    std::shared_ptr<const ViewService> service;
    httplib::Server server;
    int port = 0;
    std::set<std::string> allowed_hosts;  ///< empty: any Host (bound beyond loopback)
    std::atomic<bool> stopped{false};
};

HttpServer::HttpServer(std::shared_ptr<const ViewService> service, const ServeOptions& options)
    : impl_(std::make_unique<Impl>()) {
    options.Validate();
    impl_->service = std::move(service);
    httplib::Server& server = impl_->server;
    server.set_default_headers(
        {{"X-Content-Type-Options", "nosniff"},
         {"Cache-Control", "no-store"},
         {"Referrer-Policy", "no-referrer"},
         {"Content-Security-Policy",
          "default-src 'self'; style-src 'self' 'unsafe-inline'; img-src 'self' data: blob:"}});
    server.set_payload_max_length(0);  // GET only: a request body is never read
    // cpp-httplib's default also sets SO_REUSEPORT, with which a second `strata view` on the same
    // port would bind too and take half the requests: only SO_REUSEADDR (a quick restart).
    server.set_socket_options([](socket_t sock) {
        int yes = 1;
        ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
    });
    server.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
        if (req.method != "GET" && req.method != "HEAD") {
            Reject(res, 405, "read-only: GET and HEAD only");
            return httplib::Server::HandlerResponse::Handled;
        }
        if (!impl_->allowed_hosts.empty() &&
            !impl_->allowed_hosts.count(req.get_header_value("Host"))) {
            Reject(res, 403, "unexpected Host header");
            return httplib::Server::HandlerResponse::Handled;
        }
        return httplib::Server::HandlerResponse::Unhandled;
    });
    server.Get(".*", [this](const httplib::Request& req, httplib::Response& res) {
        Response answer = impl_->service->Get(req.path);
        res.status = answer.status;
        res.set_content(std::move(answer.body), answer.content_type.c_str());
    });
    impl_->port = options.port == 0
                      ? server.bind_to_any_port(options.bind)
                      : (server.bind_to_port(options.bind, options.port) ? options.port : -1);
    if (impl_->port <= 0) {
        throw IoError("cannot listen on " + options.bind + ":" + std::to_string(options.port) +
                      " (in use, or not an address of this machine)");
    }
    if (IsLoopback(options.bind)) {
        const std::string port = std::to_string(impl_->port);
        impl_->allowed_hosts = {"127.0.0.1:" + port, "localhost:" + port, "[::1]:" + port};
    }
}

HttpServer::~HttpServer() { Stop(); }

int HttpServer::port() const { return impl_->port; }

void HttpServer::Run() {
    if (!impl_->stopped) impl_->server.listen_after_bind();
}

void HttpServer::Stop() {
    impl_->stopped = true;
    impl_->server.stop();
}

bool HttpServer::running() const { return impl_->server.is_running(); }

}  // namespace strata::view
