// SPDX-License-Identifier: MIT
// Accepts connections on one port and hands each socket (on a strand of its own) to `on_accept`.
#pragma once

#include <functional>
#include <memory>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>

namespace turtlegas::server::detail {

class Listener : public std::enable_shared_from_this<Listener> {
 public:
  using OnAccept = std::function<void(boost::asio::ip::tcp::socket&&)>;
  /// Binds and listens; throws boost::system::system_error when the port cannot be had.
  Listener(boost::asio::io_context& ioc, const boost::asio::ip::tcp::endpoint& at, OnAccept on_accept);
  void run() { accept(); }
  void stop();
  unsigned short port() const { return acceptor_.local_endpoint().port(); }

 private:
  void accept();
  boost::asio::io_context& ioc_;
  boost::asio::ip::tcp::acceptor acceptor_;
  OnAccept on_accept_;
  boost::asio::steady_timer backoff_;  ///< after a failed accept (EMFILE): wait, do not spin
};

}  // namespace turtlegas::server::detail
