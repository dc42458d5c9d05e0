#pragma once
// One HTTP(S) GET streamed into a sink, with the failure modes of a download (no network,
// refused connection, HTTP error, stalled or cut-off transfer, Ctrl-C) turned into FetchErrors
// whose message names the URL and what happened.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

namespace neuflow::cli {

struct HttpOptions {
  long connect_timeout_s = 30;
  // Abort when fewer than 1 KiB/s arrive for this long: a stalled mirror or a dropped Wi-Fi
  // link then fails instead of hanging, while a slow but moving download continues.
  long stall_timeout_s = 60;
  // Non-empty: draw the progress (MB, percent) on stderr under this label.
  std::string progress_label;
};

// Receives the body of the final response (after redirects).
class HttpBodySink {
 public:
  virtual ~HttpBodySink() = default;
  // Once, before any write: the response's Content-Length, or -1 when the server sent none.
  virtual void begin(std::int64_t content_length) = 0;
  // Throwing aborts the transfer; http_get rethrows the exception.
  virtual void write(std::span<const std::byte> chunk) = 0;
};

// GET `url` (http or https only, redirects followed) into `sink`. On return the whole body
// was delivered, and it was as long as the Content-Length said. Throws FetchError otherwise;
// SIGINT/SIGTERM during the transfer abort it with kind kInterrupted.
void http_get(const std::string& url, HttpBodySink& sink, const HttpOptions& options);

}  // namespace neuflow::cli
