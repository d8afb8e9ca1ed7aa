// SPDX-License-Identifier: MIT
#include "session.hpp"

#include <chrono>

#include <boost/asio/post.hpp>
#include <nlohmann/json.hpp>

#include "turtlegas/server/protocol.hpp"
#include "turtlegas/turtle/json_depth.hpp"

namespace turtlegas::server::detail {

void Session::send(std::shared_ptr<const std::string> message) {
  boost::asio::post(ex_, [self = shared_from_this(), message = std::move(message)] {
    if (self->gone_) return;
    if (self->queue_.size() >= self->host_.options().limits.max_queued_replies) {
      self->gone();  // a client that never reads its replies
      self->shut();
      return;
    }
    self->queue_.push_back({message, false, false});
    self->pump();
  });
}

void Session::send_frame(std::shared_ptr<const std::string> frame, bool binary) {
  boost::asio::post(ex_, [self = shared_from_this(), frame = std::move(frame), binary] {
    if (self->gone_) return;
    if (self->frame_) ++self->frames_dropped;
    self->frame_ = Out{frame, binary, true};
    self->pump();
  });
}

void Session::close_after_send() {
  boost::asio::post(ex_, [self = shared_from_this()] {
    self->closing_ = true;
    self->frame_.reset();
    self->pump();
  });
}

void Session::pump() {
  if (writing_ || gone_) return;
  if (!queue_.empty()) {
    writing_ = std::move(queue_.front());
    queue_.pop_front();
  } else if (frame_) {
    writing_ = std::move(*frame_);
    frame_.reset();
  } else {
    if (closing_) {
      gone();
      shut();
    }
    return;
  }
  start_write(*writing_);
}

void Session::written(bool ok, std::size_t bytes) {
  if (!ok) {
    writing_.reset();
    gone();
    shut();
    return;
  }
  bytes_sent += bytes;
  if (writing_ && writing_->frame) ++frames_sent;
  writing_.reset();
  pump();
}

void Session::opened() {
  opened_ = true;
  host_.connected(std::static_pointer_cast<Client>(shared_from_this()));
}

void Session::gone() {
  if (gone_) return;
  gone_ = true;
  queue_.clear();
  frame_.reset();
  if (opened_) host_.disconnected(std::static_pointer_cast<Client>(shared_from_this()));
}

void Session::refuse(std::string_view code, std::string_view message) {
  ++local_errors;
  send(std::make_shared<const std::string>(error_text(code, message)));
}

void Session::received(std::string_view text) {
  const Limits& limits = host_.options().limits;
  const double now = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  if (now - window_start_ >= 1.0) {
    window_start_ = now;
    window_count_ = 0;
  }
  if (++window_count_ > limits.max_rate) {
    refuse("rate_limited", "more than " + std::to_string(static_cast<long long>(limits.max_rate)) +
                               " messages in a second on this connection; the message was dropped");
    return;
  }
  if (text.size() > limits.max_message) {
    refuse("too_large", "a message may have at most " + std::to_string(limits.max_message) + " bytes (this one has " +
                            std::to_string(text.size()) + "); it was skipped");
    return;
  }
  if (const auto deep = turtle::json_too_deep(text)) {
    refuse("bad_json", "a message " + *deep + " (docs/protocol.md); it was skipped");
    return;
  }
  nlohmann::json m = nlohmann::json::parse(text, nullptr, false);
  if (m.is_discarded()) {
    refuse("bad_json", "not valid JSON; a message is one JSON object, e.g. {\"type\": \"ping\"}");
    return;
  }
  host_.post(std::static_pointer_cast<Client>(shared_from_this()), std::move(m));
}

}  // namespace turtlegas::server::detail
