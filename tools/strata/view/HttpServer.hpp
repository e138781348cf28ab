#pragma once
// `strata view`'s HTTP face: the ViewService's answers over cpp-httplib (Debian's
// libcpp-httplib-dev), with the guards a local server needs.

#include <memory>
#include <string>

#include "ViewService.hpp"

namespace strata::view {

struct ServeOptions {
    std::string bind = "127.0.0.1";  ///< loopback unless the user says otherwise
    int port = 8080;                 ///< 0: any free port
    /// Validates the options; throws InvalidArgumentError naming the bad one.
    void Validate() const;
};

/// Serves GET and HEAD for the service's routes; every other method is a 405. When bound to a
/// loopback address it answers only requests whose Host is that address or localhost (a web page
/// elsewhere cannot reach the map through DNS rebinding). Answers carry nosniff and a
/// same-origin content security policy.
class HttpServer {
public:
    /// Binds the socket; @throw IoError when the address or port cannot be bound.
    HttpServer(std::shared_ptr<const ViewService> service, const ServeOptions& options);
    ~HttpServer();
    HttpServer(const HttpServer&) = delete;
    HttpServer& operator=(const HttpServer&) = delete;

    /// The bound port (the chosen one for port 0).
    [[nodiscard]] int port() const;
    /// Serves until Stop; returns at once when Stop came first.
    void Run();
    /// Stops a Run in any thread (safe to call before Run starts or more than once).
    void Stop();
    /// True while Run is accepting connections.
    [[nodiscard]] bool running() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace strata::view
