// SPDX-License-Identifier: MIT
#include "listener.hpp"

#include <chrono>

#include <boost/asio/strand.hpp>

namespace turtlegas::server::detail {

namespace asio = boost::asio;

Listener::Listener(asio::io_context& ioc, const asio::ip::tcp::endpoint& at, OnAccept on_accept)
    : ioc_(ioc), acceptor_(ioc), on_accept_(std::move(on_accept)), backoff_(ioc) {
  acceptor_.open(at.protocol());
  acceptor_.set_option(asio::socket_base::reuse_address(true));
  acceptor_.bind(at);
  acceptor_.listen(asio::socket_base::max_listen_connections);
}

void Listener::accept() {
  acceptor_.async_accept(asio::make_strand(ioc_), [self = shared_from_this()](boost::system::error_code ec, asio::ip::tcp::socket s) {
    if (ec == asio::error::operation_aborted || !self->acceptor_.is_open()) return;
    if (!ec) {
      self->on_accept_(std::move(s));
      self->accept();
      return;
    }
    // Out of descriptors (EMFILE, ENFILE) or memory: the pending connection stays in the backlog
    // and accepting again at once fails again, at 100 % CPU. Wait until some are closed.
    self->backoff_.expires_after(std::chrono::milliseconds(100));
    self->backoff_.async_wait([self](boost::system::error_code e) {
      if (!e && self->acceptor_.is_open()) self->accept();
    });
  });
}

void Listener::stop() {
  boost::system::error_code ec;
  acceptor_.close(ec);
  backoff_.cancel();
}

}  // namespace turtlegas::server::detail
