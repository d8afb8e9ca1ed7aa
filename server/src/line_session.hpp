// SPDX-License-Identifier: MIT
// A plain TCP connection carrying one JSON message per line (docs/protocol.md, "Transports").
#pragma once

#include <array>
#include <string>

#include <boost/asio/ip/tcp.hpp>

#include "session.hpp"

namespace turtlegas::server::detail {

class LineSession : public Session {
 public:
  LineSession(boost::asio::ip::tcp::socket&& socket, WorldHost& host);
  void run();
  bool binary_capable() const override { return false; }

 private:
  void start_write(const Out& out) override;
  void shut() override;
  void read();
  void take(const char* data, std::size_t n);

  boost::asio::ip::tcp::socket socket_;
  std::array<char, 64 * 1024> chunk_{};
  std::string line_;
  bool discarding_ = false;  ///< inside a line that was too long: skipped up to its end
};

}  // namespace turtlegas::server::detail
