// SPDX-License-Identifier: MIT
// What a WebSocket session and a TCP-line session share: the outgoing queue (replies in order,
// at most one frame waiting, the newest winning), the incoming checks that need no world (size,
// rate, JSON), and telling the host about the connection's life. One strand per session.
#pragma once

#include <cstddef>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include <boost/asio/any_io_executor.hpp>

#include "turtlegas/server/client.hpp"
#include "turtlegas/server/world_host.hpp"

namespace turtlegas::server::detail {

class Session : public Client, public std::enable_shared_from_this<Session> {
 public:
  Session(boost::asio::any_io_executor ex, WorldHost& host) : ex_(std::move(ex)), host_(host) {}
  void send(std::shared_ptr<const std::string> message) override;
  void send_frame(std::shared_ptr<const std::string> frame, bool binary) override;
  void close_after_send() override;

 protected:
  struct Out {
    std::shared_ptr<const std::string> data;
    bool binary = false;
    bool frame = false;
  };
  /// Starts writing `out`; the subclass calls written() when it is done.
  virtual void start_write(const Out& out) = 0;
  /// Closes the transport (after the queue drained, or on an error).
  virtual void shut() = 0;
  /// A message came in (text, without its line end): checked, parsed, handed to the host.
  void received(std::string_view text);
  /// The reply to a message refused before the host saw it.
  void refuse(std::string_view code, std::string_view message);
  void written(bool ok, std::size_t bytes);
  /// The transport failed or closed: tell the host once.
  void gone();
  void opened();

  boost::asio::any_io_executor ex_;
  WorldHost& host_;

 private:
  void pump();
  std::deque<Out> queue_;
  std::optional<Out> frame_;
  std::optional<Out> writing_;
  bool closing_ = false;
  bool gone_ = false;
  bool opened_ = false;
  double window_start_ = 0.0;
  double window_count_ = 0.0;
};

}  // namespace turtlegas::server::detail
