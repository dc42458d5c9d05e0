#include "fetch_model/http.hpp"

#include <curl/curl.h>

#include <array>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <exception>
#include <memory>
#include <mutex>
#include <stdexcept>

#include "fetch_model/error.hpp"

namespace neuflow::cli {

namespace {

constexpr long kStallBytesPerSecond = 1024;
constexpr long kMaxRedirects = 10;

volatile std::sig_atomic_t g_interrupted = 0;

extern "C" void on_interrupt(int) { g_interrupted = 1; }

// While a download runs, Ctrl-C (and a service manager's SIGTERM) only set a flag, so the
// transfer is aborted from curl's progress callback and the caller can remove its temporary
// file instead of the process dying with a partial file on disk. A signal the parent already
// ignores (nohup, background jobs) stays ignored.
class InterruptGuard {
 public:
  InterruptGuard() {
    g_interrupted = 0;
    struct sigaction action {};
    action.sa_handler = on_interrupt;
    sigemptyset(&action.sa_mask);
    for (std::size_t i = 0; i < kSignals.size(); ++i) {
      struct sigaction previous {};
      sigaction(kSignals[i], nullptr, &previous);
      installed_[i] = previous.sa_handler != SIG_IGN;
      if (installed_[i]) sigaction(kSignals[i], &action, &previous_[i]);
    }
  }
  ~InterruptGuard() {
    for (std::size_t i = 0; i < kSignals.size(); ++i) {
      if (installed_[i]) sigaction(kSignals[i], &previous_[i], nullptr);
    }
  }
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

 private:
  static constexpr std::array<int, 2> kSignals{SIGINT, SIGTERM};
  std::array<struct sigaction, 2> previous_{};
  std::array<bool, 2> installed_{};
};

void global_init() {
  static std::once_flag once;
  static CURLcode result = CURLE_OK;
  std::call_once(once, [] { result = curl_global_init(CURL_GLOBAL_DEFAULT); });
  if (result != CURLE_OK) {
    throw FetchError(FetchError::Kind::kUnavailable,
                     std::string("libcurl could not initialise: ") + curl_easy_strerror(result));
  }
}

std::string host_of(const std::string& url) {
  std::unique_ptr<CURLU, decltype(&curl_url_cleanup)> parsed(curl_url(), curl_url_cleanup);
  char* host = nullptr;
  if (!parsed || curl_url_set(parsed.get(), CURLUPART_URL, url.c_str(), 0) != CURLUE_OK ||
      curl_url_get(parsed.get(), CURLUPART_HOST, &host, 0) != CURLUE_OK) {
    return url;
  }
  std::string result = host;
  curl_free(host);
  char* port = nullptr;
  if (curl_url_get(parsed.get(), CURLUPART_PORT, &port, 0) == CURLUE_OK) {
    result += std::string(":") + port;
    curl_free(port);
  }
  return result;
}

class Progress {
 public:
  explicit Progress(std::string label) : label_(std::move(label)) {}
  ~Progress() {
    if (drawn_) std::fputc('\n', stderr);
  }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void update(curl_off_t total, curl_off_t now) {
    if (label_.empty() || now == 0 || now == shown_) return;
    const auto t = std::chrono::steady_clock::now();
    if (drawn_ && now != total && t - last_ < std::chrono::milliseconds(200)) return;
    last_ = t;
    shown_ = now;
    drawn_ = true;
    const double mb = 1e-6;
    if (total > 0) {
      std::fprintf(stderr, "\r%s: %.1f of %.1f MB (%3d%%) ", label_.c_str(), now * mb, total * mb,
                   static_cast<int>(100 * now / total));
    } else {
      std::fprintf(stderr, "\r%s: %.1f MB ", label_.c_str(), now * mb);
    }
    std::fflush(stderr);
  }

 private:
  std::string label_;
  bool drawn_ = false;
  curl_off_t shown_ = 0;
  std::chrono::steady_clock::time_point last_{};
};

struct Transfer {
  CURL* curl = nullptr;
  HttpBodySink* sink = nullptr;
  Progress* progress = nullptr;
  bool begun = false;
  std::exception_ptr error;

  void begin() {
    curl_off_t length = -1;
    if (curl_easy_getinfo(curl, CURLINFO_CONTENT_LENGTH_DOWNLOAD_T, &length) != CURLE_OK) length = -1;
    begun = true;
    sink->begin(length);
  }
};

extern "C" std::size_t on_body(char* data, std::size_t size, std::size_t count, void* user) {
  auto* transfer = static_cast<Transfer*>(user);
  try {
    // Asked here rather than from the headers: by the first body byte libcurl knows the
    // final response's length, whereas headers also arrive for every redirect.
    if (!transfer->begun) transfer->begin();
    transfer->sink->write(std::as_bytes(std::span(data, size * count)));
    return size * count;
  } catch (...) {
    transfer->error = std::current_exception();
    return 0;  // anything but size*count makes libcurl stop with CURLE_WRITE_ERROR
  }
}

extern "C" int on_progress(void* user, curl_off_t dltotal, curl_off_t dlnow, curl_off_t, curl_off_t) {
  if (g_interrupted) return 1;
  static_cast<Transfer*>(user)->progress->update(dltotal, dlnow);
  return 0;
}

[[noreturn]] void throw_for(CURLcode code, CURL* curl, const std::string& url, const char* detail_buffer,
                            const HttpOptions& options) {
  using Kind = FetchError::Kind;
  const std::string detail = detail_buffer[0] ? detail_buffer : curl_easy_strerror(code);
  switch (code) {
    case CURLE_COULDNT_RESOLVE_HOST:
      throw FetchError(Kind::kUnavailable, "offline? could not resolve " + host_of(url) + " (fetching " + url + ")");
    case CURLE_COULDNT_RESOLVE_PROXY:
      throw FetchError(Kind::kUnavailable, "could not resolve the proxy (check http_proxy/https_proxy): " + detail);
    case CURLE_COULDNT_CONNECT:
      throw FetchError(Kind::kUnavailable,
                       "offline? could not connect to " + host_of(url) + " (fetching " + url + "): " + detail);
    case CURLE_OPERATION_TIMEDOUT:
      throw FetchError(Kind::kUnavailable, url + ": timed out (" + detail + "); connect timeout " +
                                               std::to_string(options.connect_timeout_s) + " s, stall timeout " +
                                               std::to_string(options.stall_timeout_s) + " s");
    case CURLE_HTTP_RETURNED_ERROR: {
      long status = 0;
      curl_easy_getinfo(curl, CURLINFO_RESPONSE_CODE, &status);
      std::string what = "the server answered HTTP " + std::to_string(status);
      if (status == 404) what += " (not found: no such file there; check the model name and --base-url)";
      throw FetchError(Kind::kUnavailable, url + ": " + what);
    }
    case CURLE_PARTIAL_FILE:
    case CURLE_RECV_ERROR:
    case CURLE_GOT_NOTHING: {
      curl_off_t got = 0, expected = -1;
      curl_easy_getinfo(curl, CURLINFO_SIZE_DOWNLOAD_T, &got);
      curl_easy_getinfo(curl, CURLINFO_CONTENT_LENGTH_DOWNLOAD_T, &expected);
      std::string what = "the connection broke off after " + std::to_string(got) + " bytes";
      if (expected >= 0) what += " of " + std::to_string(expected);
      throw FetchError(Kind::kUnavailable, url + ": " + what + " (" + detail + "); try again");
    }
    case CURLE_TOO_MANY_REDIRECTS:
      throw FetchError(Kind::kUnavailable, url + ": more than " + std::to_string(kMaxRedirects) + " redirects");
    case CURLE_UNSUPPORTED_PROTOCOL:
      throw FetchError(Kind::kUnavailable, url + ": only http:// and https:// URLs are fetched (" + detail + ")");
    case CURLE_URL_MALFORMAT: throw FetchError(Kind::kUnavailable, url + ": not a valid URL (" + detail + ")");
    case CURLE_PEER_FAILED_VERIFICATION:
    case CURLE_SSL_CONNECT_ERROR:
    case CURLE_SSL_CACERT_BADFILE:
      throw FetchError(Kind::kUnavailable, url + ": TLS failed (" + detail +
                                               "); check the system clock and CA certificates (ca-certificates)");
    case CURLE_ABORTED_BY_CALLBACK:
      throw FetchError(Kind::kInterrupted, url + ": download interrupted, nothing was saved");
    default: throw FetchError(Kind::kUnavailable, url + ": " + detail);
  }
}

}  // namespace

void http_get(const std::string& url, HttpBodySink& sink, const HttpOptions& options) {
  global_init();
  std::unique_ptr<CURL, decltype(&curl_easy_cleanup)> curl(curl_easy_init(), curl_easy_cleanup);
  if (!curl) throw FetchError(FetchError::Kind::kUnavailable, "libcurl could not create a transfer");
  Progress progress(options.progress_label);
  Transfer transfer{curl.get(), &sink, &progress};
  char detail[CURL_ERROR_SIZE] = {};

  CURL* h = curl.get();
  curl_easy_setopt(h, CURLOPT_URL, url.c_str());
  curl_easy_setopt(h, CURLOPT_ERRORBUFFER, detail);
  // The hash is what makes the file trustworthy, but there is no reason to speak anything
  // but HTTP(S), on the first request or after a redirect.
  // The _STR options came with libcurl 7.85, which deprecated the bitmask ones; Ubuntu 22.04
  // (JetPack 6) has 7.81.
#if LIBCURL_VERSION_NUM >= 0x075500
  curl_easy_setopt(h, CURLOPT_PROTOCOLS_STR, "http,https");
  curl_easy_setopt(h, CURLOPT_REDIR_PROTOCOLS_STR, "http,https");
#else
  curl_easy_setopt(h, CURLOPT_PROTOCOLS, static_cast<long>(CURLPROTO_HTTP | CURLPROTO_HTTPS));
  curl_easy_setopt(h, CURLOPT_REDIR_PROTOCOLS, static_cast<long>(CURLPROTO_HTTP | CURLPROTO_HTTPS));
#endif
  curl_easy_setopt(h, CURLOPT_FOLLOWLOCATION, 1L);
  curl_easy_setopt(h, CURLOPT_MAXREDIRS, kMaxRedirects);
  curl_easy_setopt(h, CURLOPT_FAILONERROR, 1L);
  curl_easy_setopt(h, CURLOPT_USERAGENT, "neuflow/" NEUFLOW_VERSION " (fetch-model)");
  curl_easy_setopt(h, CURLOPT_CONNECTTIMEOUT, options.connect_timeout_s);
  curl_easy_setopt(h, CURLOPT_LOW_SPEED_LIMIT, kStallBytesPerSecond);
  curl_easy_setopt(h, CURLOPT_LOW_SPEED_TIME, options.stall_timeout_s);
  curl_easy_setopt(h, CURLOPT_WRITEFUNCTION, on_body);
  curl_easy_setopt(h, CURLOPT_WRITEDATA, &transfer);
  curl_easy_setopt(h, CURLOPT_NOPROGRESS, 0L);
  curl_easy_setopt(h, CURLOPT_XFERINFOFUNCTION, on_progress);
  curl_easy_setopt(h, CURLOPT_XFERINFODATA, &transfer);

  CURLcode code;
  {
    InterruptGuard guard;
    code = curl_easy_perform(h);
  }
  if (transfer.error) std::rethrow_exception(transfer.error);
  if (code != CURLE_OK) throw_for(code, h, url, detail, options);
  // An empty body never reaches the write callback.
  if (!transfer.begun) transfer.begin();
}

}  // namespace neuflow::cli
