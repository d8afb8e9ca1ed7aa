// SPDX-License-Identifier: MIT
#include "listener.hpp"

#include <boost/asio/strand.hpp>

namespace turtlegas::server::detail {

namespace asio = boost::asio;

Listener::Listener(asio::io_context& ioc, const asio::ip::tcp::endpoint& at, OnAccept on_accept)
    : ioc_(ioc), acceptor_(ioc), on_accept_(std::move(on_accept)) {
  acceptor_.open(at.protocol());
  acceptor_.set_option(asio::socket_base::reuse_address(true));
  acceptor_.bind(at);
  acceptor_.listen(asio::socket_base::max_listen_connections);
}

void Listener::accept() {
  acceptor_.async_accept(asio::make_strand(ioc_), [self = shared_from_this()](boost::system::error_code ec, asio::ip::tcp::socket s) {
    if (ec == asio::error::operation_aborted || !self->acceptor_.is_open()) return;
    if (!ec) self->on_accept_(std::move(s));
    self->accept();
  });
}

void Listener::stop() {
  boost::system::error_code ec;
  acceptor_.close(ec);
}

}  // namespace turtlegas::server::detail
