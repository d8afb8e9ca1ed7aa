// SPDX-License-Identifier: MIT
// A connection as the world host sees it: a WebSocket or a TCP-line session (src/session.hpp).
// Every member may be called from any thread; sends are posted to the connection's I/O strand.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

namespace turtlegas::server {

class Client {
 public:
  virtual ~Client() = default;
  /// Queues one message (a reply or a notice), in order.
  virtual void send(std::shared_ptr<const std::string> message) = 0;
  /// Queues a frame: it replaces a frame not yet being written (that one is counted as dropped).
  virtual void send_frame(std::shared_ptr<const std::string> frame, bool binary) = 0;
  /// Closes once the queued messages are written.
  virtual void close_after_send() = 0;
  /// Whether binary frames can be sent (WebSocket) or not (TCP lines).
  virtual bool binary_capable() const = 0;

  std::uint64_t id = 0;     ///< the connection's number, from 1
  bool loopback = true;     ///< the peer is on a loopback address
  std::atomic<std::uint64_t> frames_sent{0}, frames_dropped{0}, bytes_sent{0}, local_errors{0};
};

}  // namespace turtlegas::server
