/**
 * SECTION:element-neuflowsink
 * @title: neuflowsink
 *
 * Writes the optical flow attached to each video frame (#NeuflowFlowMeta, from the
 * `neuflow` element) to numbered flow files, one per frame that carries flow, like
 * `multifilesink` does for buffers. #neuflowsink:location is a printf-style pattern with
 * exactly one integer conversion for the file index (`%d`, `%05d`, `%x`...); its extension
 * picks the format: `.flo` (Middlebury), `.npy` (NumPy H×W×2 float32) or `.png` (KITTI 16-bit,
 * quantized to 1/64 px). The file holds the flow grid as it is in the meta (its own width and
 * height, vectors in pixels of the grid). Each file is written to a temporary name and
 * renamed, so a reader never sees a partial file.
 *
 * A CSV index (#neuflowsink:index-location, by default `index.csv` beside the flow files)
 * gets one row per file written, flushed at once:
 * `index,from_frame,to_frame,from_pts_ns,to_pts_ns,file,from_source,to_source` (the sources are empty here: they name image files, which only `neuflow convert` reads). The frame numbers and
 * timestamps are those of the two frames the flow was computed from; after dropped frames
 * they are not consecutive, so consumers should pair flows with frames through this file.
 *
 * #neuflowsink:max-files and #neuflowsink:max-bytes bound what a long run leaves on disk:
 * after each file written, the oldest files this element wrote (since it started) are
 * deleted until both limits hold; the newest file is always kept. With either set, the index
 * is rewritten atomically with only the rows whose files still exist whenever it holds more
 * than twice as many rows as there are files kept (and at least 32 rows), and once more when
 * the element stops: its size stays bounded at an amortized constant cost per flow.
 *
 * Buffers without flow (the first frame of a stream, frames the inference element dropped)
 * are skipped and counted in #neuflowsink:buffers-skipped. A file that cannot be written
 * (missing directory, disk full, no permission) stops the pipeline with an error naming
 * the file and the reason; the error message is posted before the flow error is returned,
 * so an application sees which sink failed before the pipeline reacts to the failure.
 *
 * As a file writer, the sink does not synchronize to the clock by default (sync=false).
 *
 * ## Example launch line
 * |[
 * gst-launch-1.0 filesrc location=in.mp4 ! decodebin ! videoconvert ! neuflow ! neuflowsink location=out/flow_%05d.flo
 * ]|
 */
#include <gst/gst.h>

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <optional>
#include <string>
#include <system_error>

#include "earlier_files.hpp"
#include "elements.hpp"
#include "flow_index_compaction.hpp"
#include "gstneuflowflowsink.hpp"
#include "neuflow/flow/errors.hpp"
#include "neuflow/flow/flow_field.hpp"
#include "neuflow/flow/flow_index.hpp"
#include "neuflow/flow/flow_io.hpp"
#include "written_files.hpp"

GST_DEBUG_CATEGORY_STATIC(gst_neuflow_sink_debug);
#define GST_CAT_DEFAULT gst_neuflow_sink_debug

enum {
  PROP_0,
  PROP_LOCATION,
  PROP_INDEX,
  PROP_INDEX_LOCATION,
  PROP_MAX_FILES,
  PROP_MAX_BYTES,
};

#define DEFAULT_PROP_LOCATION "flow_%05d.flo"
#define DEFAULT_PROP_INDEX 0
#define DEFAULT_PROP_INDEX_LOCATION nullptr /* index.csv in the directory of location */
#define DEFAULT_PROP_MAX_FILES 0            /* no limit */
#define DEFAULT_PROP_MAX_BYTES 0
#define INDEX_FILE_NAME "index.csv"
// The index is compacted when it holds more than twice the rows of the files kept, but never
// for fewer rows than this: tiny limits would otherwise rewrite it every other flow.
#define INDEX_MIN_LIVE_ROWS 16

struct GstNeuflowSink {
  GstNeuflowFlowSink parent;

  // Properties, under the object lock.
  gchar *location;
  gchar *index_location;
  gint index;         // of the next file
  guint64 max_files;  // 0: no limit
  guint64 max_bytes;

  // From start() to stop(), streaming thread only.
  gchar *pattern;     // location, validated
  gchar *index_path;  // where the index goes, or nullptr when disabled
  gchar *index_dir;   // its directory, to name files beside it by their base name
  FILE *index_file;   // opened at the first flow written

  // Retention, streaming thread only. Files are tracked only while a limit is set: without
  // one, a weeks-long run would otherwise keep one entry per flow in memory.
  neuflow::gst::WrittenFiles *written;  // files of this run, oldest first
  guint64 index_rows;                   // data rows in the index file, once counted
  gboolean index_rows_known;
  guint64 index_foreign_rows;   // rows of files not in `written` (earlier runs), at most
  guint64 index_compact_floor;  // no compaction below this many rows (after a failure)
  guint64 files_removed;        // since the last compaction
};

struct GstNeuflowSinkClass {
  GstNeuflowFlowSinkClass parent_class;
};

#define GST_NEUFLOW_SINK(obj) (reinterpret_cast<GstNeuflowSink *>(obj))

G_DEFINE_TYPE_WITH_CODE(GstNeuflowSink, gst_neuflow_sink, GST_TYPE_NEUFLOW_FLOW_SINK,
                        GST_DEBUG_CATEGORY_INIT(gst_neuflow_sink_debug, "neuflowsink", 0,
                                                "NeuFlow optical flow file writer"))

namespace {

// Checks that `pattern` holds exactly one integer conversion (%d, %i, %u, %x, %X or %o with
// optional flags, width and precision, no length modifier) and nothing else that printf
// would interpret apart from "%%". Returns a description of the problem, or nullopt.
std::optional<std::string> check_location_pattern(const char *pattern) {
  int conversions = 0;
  for (const char *p = pattern; *p; ++p) {
    if (*p != '%') continue;
    const char *start = p++;
    if (*p == '%') continue;
    while (*p && std::strchr("-+ #0", *p)) ++p;
    while (g_ascii_isdigit(*p)) ++p;
    if (*p == '.') {
      ++p;
      while (g_ascii_isdigit(*p)) ++p;
    }
    if (*p && std::strchr("diuxXo", *p)) {
      ++conversions;
      continue;
    }
    const std::string spec(start, *p ? static_cast<std::size_t>(p - start) + 1 : static_cast<std::size_t>(p - start));
    return "\"" + spec + "\" is not an integer conversion (use one of %d, %05d, %u, %x, and %% for a literal %)";
  }
  if (conversions != 1) {
    return "it must contain exactly one integer conversion such as %05d for the file index, found " +
           std::to_string(conversions);
  }
  return std::nullopt;
}

// A timestamp for the index: none when it is not known.
std::optional<std::int64_t> index_time(GstClockTime t) {
  return GST_CLOCK_TIME_IS_VALID(t) ? std::optional<std::int64_t>(static_cast<std::int64_t>(t)) : std::nullopt;
}

bool is_directory(const char *path) { return g_file_test(path, G_FILE_TEST_IS_DIR); }

}  // namespace

static void gst_neuflow_sink_set_property(GObject *object, guint prop_id, const GValue *value, GParamSpec *pspec) {
  GstNeuflowSink *self = GST_NEUFLOW_SINK(object);
  GST_OBJECT_LOCK(self);
  switch (prop_id) {
    case PROP_LOCATION:
      g_free(self->location);
      self->location = g_value_dup_string(value);
      break;
    case PROP_INDEX: self->index = g_value_get_int(value); break;
    case PROP_INDEX_LOCATION:
      g_free(self->index_location);
      self->index_location = g_value_dup_string(value);
      break;
    case PROP_MAX_FILES: self->max_files = g_value_get_uint64(value); break;
    case PROP_MAX_BYTES: self->max_bytes = g_value_get_uint64(value); break;
    default: G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec); break;
  }
  GST_OBJECT_UNLOCK(self);
}

static void gst_neuflow_sink_get_property(GObject *object, guint prop_id, GValue *value, GParamSpec *pspec) {
  GstNeuflowSink *self = GST_NEUFLOW_SINK(object);
  GST_OBJECT_LOCK(self);
  switch (prop_id) {
    case PROP_LOCATION: g_value_set_string(value, self->location); break;
    case PROP_INDEX: g_value_set_int(value, self->index); break;
    case PROP_INDEX_LOCATION: g_value_set_string(value, self->index_location); break;
    case PROP_MAX_FILES: g_value_set_uint64(value, self->max_files); break;
    case PROP_MAX_BYTES: g_value_set_uint64(value, self->max_bytes); break;
    default: G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec); break;
  }
  GST_OBJECT_UNLOCK(self);
}

static void gst_neuflow_sink_clear_run_state(GstNeuflowSink *self) {
  if (self->index_file) {
    std::fclose(self->index_file);
    self->index_file = nullptr;
  }
  g_clear_pointer(&self->pattern, g_free);
  g_clear_pointer(&self->index_path, g_free);
  g_clear_pointer(&self->index_dir, g_free);
  delete self->written;
  self->written = nullptr;
  self->index_rows = 0;
  self->index_rows_known = FALSE;
  self->index_foreign_rows = 0;
  self->index_compact_floor = 0;
  self->files_removed = 0;
}

static void gst_neuflow_sink_finalize(GObject *object) {
  GstNeuflowSink *self = GST_NEUFLOW_SINK(object);
  gst_neuflow_sink_clear_run_state(self);
  g_free(self->location);
  g_free(self->index_location);
  G_OBJECT_CLASS(gst_neuflow_sink_parent_class)->finalize(object);
}

// Deletes the oldest files until max-files and max-bytes hold. A file that cannot be deleted is
// a warning: what was written stays written.
static void gst_neuflow_sink_remove_excess(GstNeuflowSink *self, guint64 max_files, guint64 max_bytes) {
  for (const std::string &old : self->written->take_excess(max_files, max_bytes)) {
    ++self->files_removed;
    if (std::remove(old.c_str()) != 0 && errno != ENOENT) {
      const int err = errno;
      GST_ELEMENT_WARNING(self, RESOURCE, WRITE,
                          ("Could not delete the old flow file \"%s\" (max-files=%" G_GUINT64_FORMAT
                           ", max-bytes=%" G_GUINT64_FORMAT "): %s.",
                           old.c_str(), max_files, max_bytes, g_strerror(err)),
                          (nullptr));
    } else {
      GST_LOG_OBJECT(self, "deleted %s", old.c_str());
    }
  }
}

// What earlier runs left: the temporaries of writes a crash interrupted go, and with a limit
// set, the files the pattern names count towards it (oldest index first), so a restarted or
// reconfigured stream holds max-files / max-bytes over everything in the folder.
static void gst_neuflow_sink_take_over_earlier_files(GstNeuflowSink *self) {
  for (const std::string &path :
       neuflow::gst::remove_stale_temporaries(self->pattern, self->index_path ? self->index_path : "")) {
    GST_INFO_OBJECT(self, "removed %s, left by an interrupted write", path.c_str());
  }
  GST_OBJECT_LOCK(self);
  const guint64 max_files = self->max_files;
  const guint64 max_bytes = self->max_bytes;
  GST_OBJECT_UNLOCK(self);
  if (max_files == 0 && max_bytes == 0) return;
  for (const auto &file : neuflow::gst::files_matching(self->pattern)) self->written->add(file.path, file.bytes);
  gst_neuflow_sink_remove_excess(self, max_files, max_bytes);  // compacted at the latest at stop
}

// Validates the settings and checks that the output directories exist, so that a typo shows
// up when the pipeline starts rather than at the first flow. Files are created only when
// there is flow to write.
static gboolean gst_neuflow_sink_start_writing(GstNeuflowFlowSink *sink) {
  GstNeuflowSink *self = GST_NEUFLOW_SINK(sink);

  GST_OBJECT_LOCK(self);
  g_autofree gchar *location = g_strdup(self->location);
  g_autofree gchar *index_location = g_strdup(self->index_location);
  const gint index = self->index;
  GST_OBJECT_UNLOCK(self);

  if (!location || !*location) {
    GST_ELEMENT_ERROR(self, RESOURCE, NOT_FOUND, ("No location set for the flow files."),
                      ("set the location property, e.g. location=flow_%%05d.flo"));
    return FALSE;
  }
  if (auto problem = check_location_pattern(location)) {
    GST_ELEMENT_ERROR(self, RESOURCE, SETTINGS, ("Invalid flow file location \"%s\": %s.", location, problem->c_str()),
                      (nullptr));
    return FALSE;
  }
  if (!neuflow::flow::flow_format_from_path(neuflow::gst::format_index_name(location, index))) {
    GST_ELEMENT_ERROR(self, RESOURCE, SETTINGS,
                      ("Invalid flow file location \"%s\": the extension must be .flo, .npy or .png.", location),
                      (nullptr));
    return FALSE;
  }
  g_autofree gchar *dir = g_path_get_dirname(location);
  if (!is_directory(dir)) {
    GST_ELEMENT_ERROR(self, RESOURCE, OPEN_WRITE,
                      ("Cannot write flow files \"%s\": directory \"%s\" does not exist.", location, dir), (nullptr));
    return FALSE;
  }

  g_autofree gchar *index_path = nullptr;
  if (!index_location) {
    index_path = g_build_filename(dir, INDEX_FILE_NAME, nullptr);
  } else if (*index_location) {
    index_path = g_strdup(index_location);
  }
  g_autofree gchar *index_dir = index_path ? g_path_get_dirname(index_path) : nullptr;
  if (index_dir && !is_directory(index_dir)) {
    GST_ELEMENT_ERROR(self, RESOURCE, OPEN_WRITE,
                      ("Cannot write the flow index \"%s\": directory \"%s\" does not exist.", index_path, index_dir),
                      (nullptr));
    return FALSE;
  }

  GST_INFO_OBJECT(self, "writing flow to %s from index %d, index file %s", location, index,
                  index_path ? index_path : "(none)");
  gst_neuflow_sink_clear_run_state(self);
  self->written = new neuflow::gst::WrittenFiles;
  self->pattern = g_steal_pointer(&location);
  self->index_path = g_steal_pointer(&index_path);
  self->index_dir = g_steal_pointer(&index_dir);
  gst_neuflow_sink_take_over_earlier_files(self);
  return TRUE;
}

// Rewrites the index without the rows of deleted files. A failure leaves the index valid
// (only longer than it should be): it is posted as a warning, and the next attempt waits
// until the index has doubled so that a persistent problem does not cost a rewrite per flow.
static void gst_neuflow_sink_compact_index(GstNeuflowSink *self) {
  if (self->index_file) {  // reopened for appending at the next row
    std::fclose(self->index_file);
    self->index_file = nullptr;
  }
  try {
    const auto result = neuflow::gst::compact_flow_index(self->index_path, self->index_dir);
    const guint64 ours = self->written->count();
    self->index_rows = result.rows_kept;
    self->index_foreign_rows = result.rows_kept > ours ? result.rows_kept - ours : 0;
    self->index_compact_floor = 0;
    self->files_removed = 0;
    GST_DEBUG_OBJECT(self, "index %s compacted: kept %zu rows, dropped %zu", self->index_path, result.rows_kept,
                     result.rows_dropped);
  } catch (const std::exception &e) {
    GST_ELEMENT_WARNING(
        self, RESOURCE, WRITE,
        ("Could not remove the rows of deleted flow files from the index \"%s\": %s.", self->index_path, e.what()),
        (nullptr));
    self->index_compact_floor = 2 * self->index_rows;
  }
}

// After `path` (just written, with its index row) deletes the oldest files of this run until
// max-files and max-bytes hold, and compacts the index once it holds more than twice the
// rows of the files kept. Deletion problems are warnings: the flow itself was written.
static void gst_neuflow_sink_apply_retention(GstNeuflowSink *self, const std::string &path) {
  GST_OBJECT_LOCK(self);
  const guint64 max_files = self->max_files;
  const guint64 max_bytes = self->max_bytes;
  GST_OBJECT_UNLOCK(self);
  if (max_files == 0 && max_bytes == 0) return;

  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  self->written->add(path, ec ? 0 : static_cast<std::uint64_t>(size));
  gst_neuflow_sink_remove_excess(self, max_files, max_bytes);

  if (!self->index_path) return;
  if (!self->index_rows_known) {
    // Counted once, when retention first applies: the rows of earlier runs are part of it.
    self->index_rows_known = TRUE;
    try {
      self->index_rows = neuflow::gst::count_index_rows(self->index_path);
    } catch (const std::exception &e) {
      GST_WARNING_OBJECT(self, "%s", e.what());
      self->index_rows = 0;
    }
    const guint64 ours = self->written->count();
    self->index_foreign_rows = self->index_rows > ours ? self->index_rows - ours : 0;
  }
  const guint64 live = std::max<guint64>(self->index_foreign_rows + self->written->count(), INDEX_MIN_LIVE_ROWS);
  if (self->index_rows > std::max(2 * live, self->index_compact_floor)) gst_neuflow_sink_compact_index(self);
}

static void gst_neuflow_sink_stop_writing(GstNeuflowFlowSink *sink) {
  GstNeuflowSink *self = GST_NEUFLOW_SINK(sink);
  // Leaves an index that lists exactly the files kept.
  if (self->index_path && self->files_removed > 0) gst_neuflow_sink_compact_index(self);
  gst_neuflow_sink_clear_run_state(self);
}

// Whether the index file at `path` starts with this version's header line.
static bool index_has_current_header(const char *path) {
  FILE *file = std::fopen(path, "r");
  if (!file) return false;
  const std::string header = neuflow::flow::flow_index_header();
  std::string first(header.size() + 1, '\0');
  const bool read = std::fgets(first.data(), static_cast<int>(first.size()), file) != nullptr;
  std::fclose(file);
  return read && first.c_str() == header;
}

// Appends one row to the index, opening it (and writing the header into an empty file)
// the first time. Rows are appended, never rewritten: after a restart that reuses indices,
// the last row for an index describes the file now on disk.
static bool gst_neuflow_sink_append_index(GstNeuflowSink *self, gint index, const NeuflowFlowMeta *meta,
                                          const std::string &file) {
  if (!self->index_path) return true;
  if (!self->index_file) {
    // Closed by compaction too, which renames a new file over the index.
    self->index_file = std::fopen(self->index_path, "a");
    struct stat st {};
    if (!self->index_file || fstat(fileno(self->index_file), &st) != 0 ||
        (st.st_size == 0 && std::fputs(neuflow::flow::flow_index_header().c_str(), self->index_file) == EOF)) {
      const int err = errno;
      GST_ELEMENT_ERROR(self, RESOURCE, OPEN_WRITE,
                        ("Could not open the flow index \"%s\" for appending: %s.", self->index_path, g_strerror(err)),
                        (nullptr));
      return false;
    }
    // Rows are appended only under the header they belong to, never to another format's.
    if (st.st_size > 0 && !index_has_current_header(self->index_path)) {
      GST_ELEMENT_ERROR(self, RESOURCE, OPEN_WRITE,
                        ("The flow index \"%s\" has other columns than \"%s\" (written by another program or an "
                         "older neuflow); move it away or set another index-location.",
                         self->index_path, std::string(neuflow::flow::kFlowIndexColumns).c_str()),
                        (nullptr));
      std::fclose(self->index_file);
      self->index_file = nullptr;
      return false;
    }
  }

  // Files beside the index are named by their base name, so the directory can be moved.
  gchar *file_dir = g_path_get_dirname(file.c_str());
  std::string name = file;
  if (std::strcmp(file_dir, self->index_dir) == 0) {
    gchar *base = g_path_get_basename(file.c_str());
    name = base;
    g_free(base);
  }
  g_free(file_dir);

  const std::string row = neuflow::flow::flow_index_row({index, static_cast<std::int64_t>(meta->from_frame),
                                                         static_cast<std::int64_t>(meta->to_frame),
                                                         index_time(meta->from_pts), index_time(meta->to_pts), name});
  if (std::fputs(row.c_str(), self->index_file) == EOF || std::fflush(self->index_file) != 0) {
    const int err = errno;
    GST_ELEMENT_ERROR(self, RESOURCE, WRITE,
                      ("Could not append to the flow index \"%s\": %s.", self->index_path, g_strerror(err)), (nullptr));
    return false;
  }
  ++self->index_rows;
  return true;
}

static GstFlowReturn gst_neuflow_sink_write_flow(GstNeuflowFlowSink *sink, GstBuffer * /*buffer*/,
                                                 const NeuflowFlowMeta *meta, guint64 *bytes) {
  GstNeuflowSink *self = GST_NEUFLOW_SINK(sink);

  GST_OBJECT_LOCK(self);
  const gint index = self->index;
  GST_OBJECT_UNLOCK(self);
  const std::string path = neuflow::gst::format_index_name(self->pattern, index);

  try {
    neuflow::flow::FlowField field(static_cast<int>(meta->width), static_cast<int>(meta->height));
    const gfloat *vectors = neuflow_flow_meta_get_vectors(meta);
    std::memcpy(field.uv.data(), vectors, field.uv.size() * sizeof(float));
    neuflow::flow::write_flow(field, path);
  } catch (const neuflow::flow::FlowFileError &e) {
    GST_ELEMENT_ERROR(self, RESOURCE, WRITE,
                      ("Could not write the flow file \"%s\": %s.", path.c_str(), e.problem().c_str()),
                      ("%s", e.what()));
    return GST_FLOW_ERROR;
  } catch (const std::exception &e) {
    GST_ELEMENT_ERROR(self, RESOURCE, WRITE, ("Could not write the flow file \"%s\": %s.", path.c_str(), e.what()),
                      (nullptr));
    return GST_FLOW_ERROR;
  }
  GST_LOG_OBJECT(self, "wrote %s: %ux%u, frames %" G_GUINT64_FORMAT " -> %" G_GUINT64_FORMAT, path.c_str(), meta->width,
                 meta->height, meta->from_frame, meta->to_frame);
  // Measured before retention may delete the file again.
  std::error_code size_error;
  const auto size = std::filesystem::file_size(path, size_error);
  *bytes = size_error ? 0 : static_cast<guint64>(size);

  if (!gst_neuflow_sink_append_index(self, index, meta, path)) return GST_FLOW_ERROR;
  gst_neuflow_sink_apply_retention(self, path);

  GST_OBJECT_LOCK(self);
  self->index = index + 1;
  GST_OBJECT_UNLOCK(self);
  return GST_FLOW_OK;
}

static void gst_neuflow_sink_class_init(GstNeuflowSinkClass *klass) {
  GObjectClass *gobject_class = G_OBJECT_CLASS(klass);
  GstElementClass *element_class = GST_ELEMENT_CLASS(klass);
  GstNeuflowFlowSinkClass *flow_sink_class = GST_NEUFLOW_FLOW_SINK_CLASS(klass);

  gobject_class->set_property = gst_neuflow_sink_set_property;
  gobject_class->get_property = gst_neuflow_sink_get_property;
  gobject_class->finalize = gst_neuflow_sink_finalize;

  constexpr auto rw_ready =
      static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS | GST_PARAM_MUTABLE_READY);

  g_object_class_install_property(
      gobject_class, PROP_LOCATION,
      g_param_spec_string("location", "File location",
                          "Pattern of the flow file names, with exactly one printf integer conversion for the "
                          "index (e.g. flow_%05d.flo); the extension picks the format: .flo (Middlebury), .npy "
                          "(NumPy H x W x 2 float32) or .png (KITTI 16-bit). The directory must exist",
                          DEFAULT_PROP_LOCATION, rw_ready));
  g_object_class_install_property(
      gobject_class, PROP_INDEX,
      g_param_spec_int(
          "index", "Index",
          "Index of the next flow file in the location pattern; incremented after each file written "
          "(buffers without flow do not use an index)",
          0, G_MAXINT, DEFAULT_PROP_INDEX,
          static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS | GST_PARAM_MUTABLE_PLAYING)));
  g_object_class_install_property(
      gobject_class, PROP_INDEX_LOCATION,
      g_param_spec_string(
          "index-location", "Index file location",
          "CSV file that gets one row per flow file, flushed at once: "
          "index,from_frame,to_frame,from_pts_ns,to_pts_ns,file,from_source,to_source (timestamps in ns, "
          "empty when unknown; sources always empty here, the format is shared with neuflow convert; file by its base "
          "name when it lies beside the index, else as written). Rows are "
          "appended; the header is written into an empty file. With max-files or max-bytes set, the "
          "index is rewritten atomically with only the rows of files still on disk whenever it holds "
          "more than twice as many rows as files kept (at least 32 rows), and when the element "
          "stops, so it stays bounded. Unset: index.csv in the directory of location; empty string: "
          "no index",
          DEFAULT_PROP_INDEX_LOCATION, rw_ready));
  g_object_class_install_property(
      gobject_class, PROP_MAX_FILES,
      g_param_spec_uint64(
          "max-files", "Maximum files",
          "Keep at most this many flow files: after each file written, the oldest files this element "
          "wrote since it started (not those of earlier runs, nor those written while no limit was "
          "set) are deleted, oldest first, and their index rows dropped. 0: no limit",
          0, G_MAXUINT64, DEFAULT_PROP_MAX_FILES,
          static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS | GST_PARAM_MUTABLE_PLAYING)));
  g_object_class_install_property(
      gobject_class, PROP_MAX_BYTES,
      g_param_spec_uint64(
          "max-bytes", "Maximum bytes",
          "Keep the flow files at most this many bytes in all, deleting the oldest as for max-files "
          "(both limits hold when both are set); the newest file is always kept, even when it alone "
          "is larger. 0: no limit",
          0, G_MAXUINT64, DEFAULT_PROP_MAX_BYTES,
          static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS | GST_PARAM_MUTABLE_PLAYING)));

  gst_element_class_set_static_metadata(element_class, "NeuFlow optical flow file sink", "Sink/File/Video/Analyzer",
                                        "Writes the optical flow attached to video frames (NeuflowFlowMeta) to "
                                        "numbered .flo, .npy or KITTI .png files with a CSV index",
                                        "neuflow");
  gst_element_class_add_static_metadata(element_class, GST_ELEMENT_METADATA_DOC_URI, NEUFLOW_DOC_URI);
  flow_sink_class->start_writing = GST_DEBUG_FUNCPTR(gst_neuflow_sink_start_writing);
  flow_sink_class->write_flow = GST_DEBUG_FUNCPTR(gst_neuflow_sink_write_flow);
  flow_sink_class->stop_writing = GST_DEBUG_FUNCPTR(gst_neuflow_sink_stop_writing);
  flow_sink_class->written_noun = "flow files";
}

static void gst_neuflow_sink_init(GstNeuflowSink *self) {
  self->location = g_strdup(DEFAULT_PROP_LOCATION);
  self->index_location = DEFAULT_PROP_INDEX_LOCATION;
  self->index = DEFAULT_PROP_INDEX;
  self->max_files = DEFAULT_PROP_MAX_FILES;
  self->max_bytes = DEFAULT_PROP_MAX_BYTES;
  // The run's state as after a run: GObject zeroes a new instance, so there is nothing to free.
  gst_neuflow_sink_clear_run_state(self);
}

GST_ELEMENT_REGISTER_DEFINE(neuflowsink, "neuflowsink", GST_RANK_NONE, gst_neuflow_sink_get_type());
