// SPDX-License-Identifier: MIT
// The server's limits (docs/protocol.md, "Limits"), set from `turtlegas serve`'s options.
#pragma once

#include <cstddef>

namespace turtlegas::server {

struct Limits {
  std::size_t max_message = 1024 * 1024;   ///< bytes of one message (a line, a WebSocket message)
  /// Above this a WebSocket message is not read at all: the connection is closed (1009).
  std::size_t max_websocket_read = 16 * 1024 * 1024;
  double max_rate = 20000;                 ///< messages per second per connection
  std::size_t max_clients = 64;            ///< WebSocket and TCP-line connections together
  std::size_t max_claims = 8;              ///< claimed turtles per connection
  std::size_t max_queued_replies = 4096;   ///< a connection that lets more pile up is closed
  std::size_t max_frame_events = 10000;    ///< events per frame; the rest are counted
};

}  // namespace turtlegas::server
