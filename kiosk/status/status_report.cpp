#include "kiosk/status/status_report.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "kiosk/status/build_info.h"

namespace basalt::kiosk {

namespace {

double unixSeconds(WallTime t) { return std::chrono::duration<double>(t.time_since_epoch()).count(); }

std::string isoTime(WallTime t) {
  const auto seconds = std::chrono::floor<std::chrono::seconds>(t);
  const std::int64_t s = seconds.time_since_epoch().count();
  std::int64_t days = s / 86400;
  std::int64_t rest = s % 86400;
  if (rest < 0) {
    rest += 86400;
    --days;
  }
  // Civil date from days since 1970 (Howard Hinnant's algorithm).
  days += 719468;
  const std::int64_t era = (days >= 0 ? days : days - 146096) / 146097;
  const auto doe = static_cast<unsigned>(days - era * 146097);
  const unsigned yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  const unsigned doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const unsigned mp = (5 * doy + 2) / 153;
  const unsigned d = doy - (153 * mp + 2) / 5 + 1;
  const unsigned m = mp < 10 ? mp + 3 : mp - 9;
  const std::int64_t y = static_cast<std::int64_t>(yoe) + era * 400 + (m <= 2 ? 1 : 0);
  return fmt::format("{:04}-{:02}-{:02}T{:02}:{:02}:{:02}Z", y, m, d, rest / 3600, rest / 60 % 60, rest % 60);
}

/// Insertion-ordered, so that the documents read in the order they are written.
using Json = nlohmann::ordered_json;

/// `value` rounded to `decimals` places: figures as precise as they are meaningful. NaN and the
/// infinities stay as they are (and are written as null).
double rounded(double value, int decimals) {
  if (!std::isfinite(value)) return value;
  const double scale = std::pow(10.0, decimals);
  return std::round(value * scale) / scale;
}

/// Valid JSON whatever the strings hold: control characters are escaped, and bytes that are
/// not UTF-8 (a device's name, a log line from a driver) become U+FFFD; NaN is written as null.
std::string dumpJson(const Json& json, int indent) {
  return json.dump(indent, ' ', false, Json::error_handler_t::replace);
}

std::string logLine(const log::Record& r) {
  return fmt::format("{} {} {}: {}", isoTime(r.wallTime), log::levelName(r.level), r.category, r.message);
}

/// The states overallState() returns, each a series of basalt_state.
constexpr std::array<std::string_view, 2> kStates{"ok", "degraded"};

constexpr std::string_view kDeviceStateHelp =
    "The device's state as a number: 0 absent, 1 opening, 2 live, 3 lost, 4 reopening, 5 idle (a camera no "
    "texture shows), -1 another.";
constexpr std::string_view kStreamStateHelp =
    "The stream's state as a number: 0 absent, 1 waiting, 2 playing, 3 lost, 4 degraded (its content is broken), "
    "-1 another.";

int deviceStateNumber(std::string_view state) {
  constexpr std::array<std::string_view, 6> kNames{"absent", "opening", "live", "lost", "reopening", "idle"};
  const auto it = std::find(kNames.begin(), kNames.end(), state);
  return it == kNames.end() ? -1 : static_cast<int>(it - kNames.begin());
}

int streamStateNumber(std::string_view state) {
  constexpr std::array<std::string_view, 5> kNames{"absent", "waiting", "playing", "lost", "degraded"};
  const auto it = std::find(kNames.begin(), kNames.end(), state);
  return it == kNames.end() ? -1 : static_cast<int>(it - kNames.begin());
}

/// A sample's value as Prometheus' text format writes it (NaN, +Inf, -Inf included), exact
/// enough to read back.
std::string number(double value) {
  if (std::isnan(value)) return "NaN";
  if (std::isinf(value)) return value > 0 ? "+Inf" : "-Inf";
  return fmt::format("{}", value);
}

std::string promLabel(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (c == '\\' || c == '"') {
      out += '\\';
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else {
      out += c;
    }
  }
  return out;
}

}  // namespace

std::string jsonString(std::string_view text) { return dumpJson(Json(text), -1); }

std::string_view overallState(const StatusSnapshot& s) {
  // The show's own errors (at start, or at a failed reload) come first.
  if (!s.problems.empty()) return "degraded";
  for (const DeviceStatus& d : s.devices) {
    // "idle": a camera no texture shows (a script may open it); nothing is wrong with it.
    if (d.state != "live" && d.state != "idle") return "degraded";
  }
  for (const StreamStatus& st : s.streams) {
    if (st.state != "playing") return "degraded";
  }
  // A frame-locked node: a follower without its leader, a leader missing a follower it knew.
  if (s.lock && (s.lock->leader ? s.lock->followers < s.lock->followersKnown : !s.lock->leaderPresent)) {
    return "degraded";
  }
  return "ok";
}

std::string healthJson(const StatusSnapshot& s) {
  const FrameFigures& f = s.frames;
  Json out;
  out["state"] = overallState(s);
  out["time"] = isoTime(s.now);
  out["uptime_seconds"] = rounded(std::chrono::duration<double>(s.now - s.startedAt).count(), 3);
  const ShowStatus& sh = s.show;
  out["show"] = {{"name", sh.name},
                 {"manifest", sh.manifest},
                 {"output", sh.output},
                 {"open", sh.open},
                 {"mode", sh.mode},
                 {"display", sh.display},
                 {"item", sh.item},
                 {"index", sh.index},
                 {"count", sh.count},
                 {"description", sh.description},
                 {"next_schedule_change", sh.nextScheduleChange ? Json(isoTime(*sh.nextScheduleChange)) : Json()}};
  const auto milliseconds = [](double p50, double p90, double p99, double max) {
    return Json{{"p50", rounded(p50 * 1e3, 3)},
                {"p90", rounded(p90 * 1e3, 3)},
                {"p99", rounded(p99 * 1e3, 3)},
                {"max", rounded(max * 1e3, 3)}};
  };
  out["frames"] = {{"total", f.frames},
                   {"per_second", rounded(f.framesPerSecond, 2)},
                   {"frame_time_ms", milliseconds(f.intervalP50, f.intervalP90, f.intervalP99, f.intervalMax)},
                   {"work_ms", milliseconds(f.workP50, f.workP90, f.workP99, f.workMax)},
                   {"window", f.window},
                   {"late", f.lateFrames},
                   {"dropped", f.droppedFrames},
                   {"missed_at_reload", f.missedAtReload},
                   {"input_events_dropped", f.inputDropped}};
  // LAVA's performance meter (manual §9): the last sampled frame's counts, rates over the sample.
  const runtime::PerformanceMeter& m = s.performance;
  out["performance"] = {{"triangles", m.triangles},
                        {"lines", m.lines},
                        {"points", m.points},
                        {"parts", m.parts},
                        {"facets", m.facets},
                        {"fps", rounded(m.framesPerSecond, 2)},
                        {"primitives_per_second", rounded(m.primitivesPerSecond, 0)},
                        {"sample_seconds", rounded(m.samplePeriodSeconds, 1)},
                        {"samples", m.updates}};
  if (const std::optional<FrameLockFigures>& l = s.lock) {
    out["lock"] = {
        {"role", l->leader ? "leader" : "follower"},
        {"node", l->node},
        {"followers", l->followers},
        {"followers_known", l->followersKnown},
        {"barrier_timeouts", l->barrierTimeouts},
        {"followers_dropped", l->followersDropped},
        {"followers_rejoined", l->followersRejoined},
        {"late_answers", l->lateAnswers},
        {"barrier_wait_ms", {{"p50", rounded(l->barrierWaitP50Ms, 3)}, {"max", rounded(l->barrierWaitMaxMs, 3)}}},
        {"leader_present", l->leaderPresent},
        {"leader_lost", l->leaderLost},
        {"frames_drawn", l->framesDrawn},
        {"last_frame", l->lastFrame},
        {"skipped", l->skipped},
        {"presents_missed", l->presentsMissed},
        {"skew_frames_max", l->maxSkewFrames},
        {"clock_offset_us", l->leader ? l->maxClockOffsetUs : l->clockOffsetUs},
        {"delay_ms", {{"p50", rounded(l->delayP50Ms, 3)}, {"max", rounded(l->delayMaxMs, 3)}}},
        {"malformed", l->malformed},
        {"authenticated", l->authenticated},
        {"rejected",
         {{"no_key", l->rejected.noKey},
          {"wrong_key", l->rejected.wrongKey},
          {"handshake", l->rejected.handshake},
          {"frame_jump", l->rejected.frameJump},
          {"out_of_sequence", l->rejected.outOfSequence},
          {"followers_full", l->rejected.followersFull}}},
        {"holding", l->holding},
        {"holding_seconds", rounded(l->holdingSeconds, 1)},
        {"held_frame", l->heldFrame},
        {"leader_returned", l->leaderReturned},
        {"leader_restarts", l->leaderRestarts},
        {"watchdog_pings_holding", l->watchdogPingsHolding},
        {"programme_changes", l->programmeChanges},
        {"commands_applied", l->commandsApplied},
        {"commands_resent", l->commandsResent},
        {"commands_lost", l->commandsLost},
        {"movie_frames_corrected", l->movieFramesCorrected},
        {"movie_frames_late", l->movieFramesLate}};
  }
  if (const std::optional<OscFigures>& o = s.osc) {
    out["osc"] = {{"listen", o->listen},
                  {"received", o->received},
                  {"acted", o->acted},
                  {"refused",
                   {{"unmatched", o->unmatched},
                    {"wrong_types", o->wrongTypes},
                    {"bad_argument", o->badArgument},
                    {"refused_sender", o->refusedSender},
                    {"rate_limited", o->rateLimited},
                    {"queue_full", o->queueFull},
                    {"malformed", o->malformed}}},
                  {"sent", o->sent},
                  {"send_failed", o->sendFailed}};
  }
  Json& devices = out["devices"] = Json::array();
  for (const DeviceStatus& d : s.devices) {
    devices.push_back({{"name", d.name},
                       {"kind", d.kind},
                       {"backend", d.backend},
                       {"state", d.state},
                       {"since", isoTime(d.since)},
                       {"message", d.message}});
  }
  Json& streams = out["streams"] = Json::array();
  for (const StreamStatus& st : s.streams) {
    streams.push_back({{"name", st.name},
                       {"kind", st.kind},
                       {"state", st.state},
                       {"since", isoTime(st.since)},
                       {"message", st.message}});
  }
  out["reloads"] = {{"total", s.reloads}, {"failed", s.reloadFailures}, {"last", s.lastReload}};
  out["problems"] = s.problems;
  out["errors_logged"] = s.errorsLogged;
  Json& errors = out["last_errors"] = Json::array();
  for (const log::Record& r : s.lastErrors) {
    errors.push_back({{"time", isoTime(r.wallTime)},
                      {"level", log::levelName(r.level)},
                      {"category", r.category},
                      {"message", r.message}});
  }
  Json& tail = out["log_tail"] = Json::array();
  const std::size_t first = s.logTail.size() > 30 ? s.logTail.size() - 30 : 0;
  for (std::size_t i = first; i < s.logTail.size(); ++i) tail.push_back(logLine(s.logTail[i]));
  if (const std::optional<ServerFacts>& server = s.server) {
    out["server"] = {{"controls", server->controls}, {"snapshot", server->snapshot}, {"read_token", server->readToken}};
  }
  const BuildInfo build = buildInfo();
  out["build"] = {{"version", build.version}, {"revision", build.revision}, {"build", build.build}};
  if (const std::optional<ProcessFigures>& p = s.process) {
    out["process"] = {
        {"resident_bytes", p->residentBytes}, {"open_fds", p->openFds}, {"cpu_seconds", rounded(p->cpuSeconds, 2)}};
  }
  if (const std::optional<MachineFacts>& machine = s.machine) {
    Json addresses = Json::array();
    for (const NetworkAddress& a : machine->addresses)
      addresses.push_back({{"interface", a.interface}, {"address", a.address}});
    Json disks = Json::array();
    for (const DiskFacts& d : machine->disks) {
      disks.push_back({{"name", d.name},
                       {"path", d.path},
                       {"total_bytes", d.totalBytes},
                       {"free_bytes", d.freeBytes},
                       {"error", d.error.empty() ? Json() : Json(d.error)}});
    }
    Json temperature;  // null: no sensor
    if (machine->cpuTemperature) {
      temperature = {{"celsius", rounded(machine->cpuTemperature->celsius, 1)},
                     {"sensor", machine->cpuTemperature->sensor}};
    }
    out["machine"] = {
        {"hostname", machine->hostname},
        {"addresses", std::move(addresses)},
        {"uptime_seconds", rounded(machine->uptimeSeconds, 0)},
        {"memory", {{"total_bytes", machine->memoryTotalBytes}, {"available_bytes", machine->memoryAvailableBytes}}},
        {"disks", std::move(disks)},
        {"cpu_temperature", std::move(temperature)}};
  }
  return dumpJson(out, 2) + "\n";
}

std::string logText(const std::vector<log::Record>& records) {
  std::string out;
  for (const log::Record& r : records) {
    out += logLine(r);
    out += '\n';
  }
  return out;
}

std::string metricsText(const StatusSnapshot& s, const ServerCounters& server) {
  const FrameFigures& f = s.frames;
  std::string out;
  const auto metric = [&out](std::string_view name, std::string_view type, std::string_view help) {
    out += fmt::format("# HELP {} {}\n# TYPE {} {}\n", name, help, name, type);
  };
  const BuildInfo build = buildInfo();
  metric("basalt_build_info", "gauge", "Basalt's version and source revision, as labels; always 1.");
  out += fmt::format("basalt_build_info{{version=\"{}\",revision=\"{}\"}} 1\n", promLabel(build.version),
                     promLabel(build.revision));
  metric("basalt_up", "gauge", "1 while the show runs (from its first frame on), 0 before; basalt_state says how.");
  out += fmt::format("basalt_up {}\n", f.frames > 0 ? 1 : 0);
  metric("basalt_state", "gauge",
         "1 for the show's state (\"ok\", or \"degraded\": a device, stream or frame-lock peer is missing).");
  const std::string_view state = overallState(s);
  for (const std::string_view known : kStates) {
    out += fmt::format("basalt_state{{state=\"{}\"}} {}\n", known, state == known ? 1 : 0);
  }
  metric("basalt_start_time_seconds", "gauge", "When the process started, in seconds since 1970.");
  out += fmt::format("basalt_start_time_seconds {:.3f}\n", unixSeconds(s.startedAt));
  metric("basalt_uptime_seconds", "gauge", "Seconds since the process started.");
  out += fmt::format("basalt_uptime_seconds {:.3f}\n", std::chrono::duration<double>(s.now - s.startedAt).count());
  metric("basalt_frames_total", "counter", "Frames presented.");
  out += fmt::format("basalt_frames_total {}\n", f.frames);
  metric("basalt_frames_late_total", "counter", "Frames presented more than 1.5 frame periods after the previous.");
  out += fmt::format("basalt_frames_late_total {}\n", f.lateFrames);
  metric("basalt_frames_missed_at_reload_total", "counter", "Late frames in the three frames after a reload.");
  out += fmt::format("basalt_frames_missed_at_reload_total {}\n", f.missedAtReload);
  metric("basalt_frames_per_second", "gauge", "Frames per second over the recent window.");
  out += fmt::format("basalt_frames_per_second {:.3f}\n", f.framesPerSecond);
  metric("basalt_frame_interval_seconds", "histogram", "Time from one present to the next.");
  for (std::size_t i = 0; i < kFrameIntervalBuckets.size(); ++i) {
    out += fmt::format("basalt_frame_interval_seconds_bucket{{le=\"{}\"}} {}\n", kFrameIntervalBuckets[i],
                       f.intervalBuckets[i]);
  }
  out += fmt::format("basalt_frame_interval_seconds_bucket{{le=\"+Inf\"}} {}\n", f.intervalCount);
  out += fmt::format("basalt_frame_interval_seconds_sum {}\n", number(f.intervalSum));
  out += fmt::format("basalt_frame_interval_seconds_count {}\n", f.intervalCount);
  metric("basalt_frame_work_seconds", "summary",
         "The frame loop's own work per frame: quantiles over the recent frames, sum and count since the start.");
  for (const auto& [q, v] : {std::pair{"0.5", f.workP50}, {"0.9", f.workP90}, {"0.99", f.workP99}}) {
    out += fmt::format("basalt_frame_work_seconds{{quantile=\"{}\"}} {}\n", q, number(v));
  }
  out += fmt::format("basalt_frame_work_seconds_sum {}\n", number(f.workSum));
  out += fmt::format("basalt_frame_work_seconds_count {}\n", f.workCount);
  metric("basalt_frame_work_cpu_seconds", "summary",
         "The frame loop thread's CPU time per frame (its work without preemption), since the start.");
  out += fmt::format("basalt_frame_work_cpu_seconds_sum {}\n", number(f.cpuSum));
  out += fmt::format("basalt_frame_work_cpu_seconds_count {}\n", f.workCount);
  metric("basalt_frame_interval_at_reload_max_seconds", "gauge",
         "The longest present-to-present in the three frames after a reload took over.");
  out += fmt::format("basalt_frame_interval_at_reload_max_seconds {:.6f}\n", f.longestAtReload);
  metric("basalt_input_events_dropped_total", "counter", "Input events lost to a full queue.");
  out += fmt::format("basalt_input_events_dropped_total {}\n", f.inputDropped);
  metric("basalt_frames_dropped_total", "counter",
         "Display refreshes that showed no new frame (a present k periods after the previous drops k - 1).");
  out += fmt::format("basalt_frames_dropped_total {}\n", f.droppedFrames);
  const runtime::PerformanceMeter& m = s.performance;
  metric("basalt_performance_primitives", "gauge",
         "LAVA's performance meter: primitives drawn in the last sampled frame, by kind.");
  for (const auto& [kind, n] : {std::pair{"triangles", m.triangles}, {"lines", m.lines}, {"points", m.points}}) {
    out += fmt::format("basalt_performance_primitives{{kind=\"{}\"}} {}\n", kind, n);
  }
  metric("basalt_performance_parts", "gauge", "LAVA's performance meter: parts drawn in the last sampled frame.");
  out += fmt::format("basalt_performance_parts {}\n", m.parts);
  metric("basalt_performance_facets", "gauge", "LAVA's performance meter: facets (views) drawn in the last frame.");
  out += fmt::format("basalt_performance_facets {}\n", m.facets);
  metric("basalt_performance_frames_per_second", "gauge",
         "LAVA's performance meter: frames per second over its sample.");
  out += fmt::format("basalt_performance_frames_per_second {:.3f}\n", m.framesPerSecond);
  metric("basalt_performance_primitives_per_second", "gauge",
         "LAVA's performance meter: primitives per second over its sample.");
  out += fmt::format("basalt_performance_primitives_per_second {:.0f}\n", m.primitivesPerSecond);
  metric("basalt_kiosk_open", "gauge", "1 within opening hours.");
  out += fmt::format("basalt_kiosk_open {}\n", s.show.open ? 1 : 0);
  metric("basalt_kiosk_mode", "gauge", "1 for the kiosk's current mode.");
  for (const char* mode : {"closed", "attract", "active"}) {
    out += fmt::format("basalt_kiosk_mode{{mode=\"{}\"}} {}\n", mode, s.show.mode == mode ? 1 : 0);
  }
  metric("basalt_display_on", "gauge", "1 while the display shows the show (0 black or switched off).");
  out += fmt::format("basalt_display_on {}\n", s.show.display == "on" ? 1 : 0);
  metric("basalt_item_info", "gauge", "The item playing now.");
  out += fmt::format("basalt_item_info{{show=\"{}\",item=\"{}\",index=\"{}\",count=\"{}\"}} 1\n",
                     promLabel(s.show.name), promLabel(s.show.item), s.show.index, s.show.count);
  // A device's and a stream's series keep their labels whatever their state: the state is a value.
  metric("basalt_device_info", "gauge", "The show's devices: kind and backend as labels; always 1.");
  for (const DeviceStatus& d : s.devices) {
    out += fmt::format("basalt_device_info{{device=\"{}\",kind=\"{}\",backend=\"{}\"}} 1\n", promLabel(d.name),
                       promLabel(d.kind), promLabel(d.backend));
  }
  metric("basalt_device_up", "gauge", "1 while the device is live.");
  for (const DeviceStatus& d : s.devices) {
    out += fmt::format("basalt_device_up{{device=\"{}\"}} {}\n", promLabel(d.name), d.state == "live" ? 1 : 0);
  }
  metric("basalt_device_state", "gauge", std::string(kDeviceStateHelp));
  for (const DeviceStatus& d : s.devices) {
    out += fmt::format("basalt_device_state{{device=\"{}\"}} {}\n", promLabel(d.name), deviceStateNumber(d.state));
  }
  metric("basalt_device_state_since_seconds", "gauge", "When the device entered its state, seconds since 1970.");
  for (const DeviceStatus& d : s.devices) {
    out += fmt::format("basalt_device_state_since_seconds{{device=\"{}\"}} {:.3f}\n", promLabel(d.name),
                       unixSeconds(d.since));
  }
  metric("basalt_stream_info", "gauge", "The show's streams (movies, camera textures): kind as a label; always 1.");
  for (const StreamStatus& st : s.streams) {
    out += fmt::format("basalt_stream_info{{stream=\"{}\",kind=\"{}\"}} 1\n", promLabel(st.name), promLabel(st.kind));
  }
  metric("basalt_stream_up", "gauge", "1 while the stream plays.");
  for (const StreamStatus& st : s.streams) {
    out += fmt::format("basalt_stream_up{{stream=\"{}\"}} {}\n", promLabel(st.name), st.state == "playing" ? 1 : 0);
  }
  metric("basalt_stream_state", "gauge", std::string(kStreamStateHelp));
  for (const StreamStatus& st : s.streams) {
    out += fmt::format("basalt_stream_state{{stream=\"{}\"}} {}\n", promLabel(st.name), streamStateNumber(st.state));
  }
  if (const std::optional<TrackerFigures>& t = s.tracker) {
    const std::string label = promLabel(t->tracker);
    metric("basalt_tracker_samples_total", "counter", "Tracker samples the viewer took.");
    out += fmt::format("basalt_tracker_samples_total{{tracker=\"{}\"}} {}\n", label, t->samples);
    metric("basalt_tracker_samples_dropped_total", "counter", "Tracker samples dropped before a frame took them.");
    out += fmt::format("basalt_tracker_samples_dropped_total{{tracker=\"{}\"}} {}\n", label, t->dropped);
    metric("basalt_tracker_latency_seconds", "summary",
           "Sample time to the frame that first draws with it (the newest sample a frame uses).");
    out += fmt::format("basalt_tracker_latency_seconds_sum{{tracker=\"{}\"}} {}\n", label, number(t->latencySum));
    out += fmt::format("basalt_tracker_latency_seconds_count{{tracker=\"{}\"}} {}\n", label, t->frames);
    metric("basalt_tracker_latency_last_seconds", "gauge", "The last frame's sample-to-frame latency.");
    out += fmt::format("basalt_tracker_latency_last_seconds{{tracker=\"{}\"}} {}\n", label,
                       number(std::chrono::duration<double>(t->lastLatency).count()));
    metric("basalt_tracker_latency_max_seconds", "gauge", "The largest sample-to-frame latency so far.");
    out += fmt::format("basalt_tracker_latency_max_seconds{{tracker=\"{}\"}} {}\n", label,
                       number(std::chrono::duration<double>(t->maxLatency).count()));
  }
  if (const std::optional<FrameLockFigures>& l = s.lock) {
    const auto lockMetric = [&](std::string_view name, std::string_view type, std::string_view help, auto value) {
      metric(name, type, help);
      out += fmt::format("{}{{node=\"{}\",role=\"{}\"}} {}\n", name, promLabel(l->node),
                         l->leader ? "leader" : "follower", value);
    };
    if (l->leader) {
      lockMetric("basalt_lock_followers", "gauge", "Followers in the frame barrier now.", l->followers);
      lockMetric("basalt_lock_barrier_timeouts_total", "counter",
                 "Frames the leader presented without every follower's answer.", l->barrierTimeouts);
      lockMetric("basalt_lock_followers_dropped_total", "counter", "Times a follower left the barrier.",
                 l->followersDropped);
      lockMetric("basalt_lock_late_answers_total", "counter", "Followers' answers for frames already presented.",
                 l->lateAnswers);
      lockMetric("basalt_lock_barrier_wait_seconds", "gauge", "The leader's median wait for the answers.",
                 number(l->barrierWaitP50Ms / 1e3));
    } else {
      lockMetric("basalt_lock_leader_present", "gauge", "1 while the leader is heard.", l->leaderPresent ? 1 : 0);
      lockMetric("basalt_lock_leader_lost_total", "counter", "Times the leader went quiet.", l->leaderLost);
      lockMetric("basalt_lock_holding", "gauge", "1 while this follower holds its picture for a lost leader.",
                 l->holding ? 1 : 0);
      lockMetric("basalt_lock_leader_returned_total", "counter", "Times a lost leader came back.", l->leaderReturned);
      lockMetric("basalt_lock_leader_restarts_total", "counter", "Times the leader's frames came from a new run of it.",
                 l->leaderRestarts);
      lockMetric("basalt_lock_frames_skipped_total", "counter", "Leader frames this follower passed over.", l->skipped);
      lockMetric("basalt_lock_presents_missed_total", "counter", "Frames presented without the leader's word.",
                 l->presentsMissed);
      lockMetric("basalt_lock_skew_frames_max", "gauge", "Largest lead of the leader's presented frame over ours.",
                 l->maxSkewFrames);
      lockMetric("basalt_lock_clock_offset_seconds", "gauge", "The shared clock minus this node's clock.",
                 number(static_cast<double>(l->clockOffsetUs) / 1e6));
    }
    lockMetric("basalt_lock_malformed_total", "counter", "Frame-lock messages rejected.", l->malformed);
    lockMetric("basalt_lock_authenticated", "gauge", "1 when every frame-lock connection proves the group's key.",
               l->authenticated ? 1 : 0);
    metric("basalt_lock_messages_rejected_total", "counter",
           "Frame-lock connections and messages refused, by reason; none of them changed the show.");
    for (const auto& [reason, count] : {std::pair<std::string_view, std::int64_t>{"no_key", l->rejected.noKey},
                                        {"wrong_key", l->rejected.wrongKey},
                                        {"handshake", l->rejected.handshake},
                                        {"frame_jump", l->rejected.frameJump},
                                        {"out_of_sequence", l->rejected.outOfSequence},
                                        {"followers_full", l->rejected.followersFull}}) {
      out += fmt::format("basalt_lock_messages_rejected_total{{node=\"{}\",role=\"{}\",reason=\"{}\"}} {}\n",
                         promLabel(l->node), l->leader ? "leader" : "follower", reason, count);
    }
    lockMetric("basalt_lock_commands_applied_total", "counter",
               l->leader ? "Script commands the leader ran for the group." : "The leader's script commands run here.",
               l->commandsApplied);
    lockMetric("basalt_lock_commands_resent_total", "counter",
               l->leader ? "Commands re-sent to followers that missed them." : "Commands the leader re-sent here.",
               l->commandsResent);
    if (!l->leader) {
      lockMetric("basalt_lock_commands_lost_total", "counter",
                 "The leader's commands gone from its log before this node had them.", l->commandsLost);
      lockMetric("basalt_lock_movie_frames_corrected_total", "counter",
                 "Movie frames shown by the leader's number that this node's own timeline would not have picked.",
                 l->movieFramesCorrected);
      lockMetric("basalt_lock_movie_frames_late_total", "counter",
                 "The leader's movie frames not decoded here in time (the frame before stayed).", l->movieFramesLate);
    }
  }
  if (const std::optional<OscFigures>& o = s.osc) {
    metric("basalt_osc_messages_total", "counter",
           "OSC messages received, by outcome: acted on, or refused (none of those changed the show).");
    for (const auto& [outcome, count] : {std::pair<std::string_view, std::uint64_t>{"acted", o->acted},
                                         {"unmatched", o->unmatched},
                                         {"wrong_types", o->wrongTypes},
                                         {"bad_argument", o->badArgument},
                                         {"refused_sender", o->refusedSender},
                                         {"rate_limited", o->rateLimited},
                                         {"queue_full", o->queueFull},
                                         {"malformed", o->malformed}}) {
      out += fmt::format("basalt_osc_messages_total{{outcome=\"{}\"}} {}\n", outcome, count);
    }
    metric("basalt_osc_sent_total", "counter", "OSC messages sent to the show's [[osc.send]] destinations.");
    out += fmt::format("basalt_osc_sent_total {}\n", o->sent);
    metric("basalt_osc_send_failures_total", "counter", "OSC messages that could not be sent.");
    out += fmt::format("basalt_osc_send_failures_total {}\n", o->sendFailed);
  }
  metric("basalt_reloads_total", "counter", "Reloads asked for (SIGHUP or the control server).");
  out += fmt::format("basalt_reloads_total {}\n", s.reloads);
  metric("basalt_reload_failures_total", "counter", "Reloads that failed; the old show played on.");
  out += fmt::format("basalt_reload_failures_total {}\n", s.reloadFailures);
  metric("basalt_errors_logged_total", "counter", "Error records logged.");
  out += fmt::format("basalt_errors_logged_total {}\n", s.errorsLogged);
  metric("basalt_http_requests_total", "counter", "Requests the status server received.");
  out += fmt::format("basalt_http_requests_total {}\n", server.requests);
  metric("basalt_http_rejected_total", "counter", "Requests the status server refused, by reason.");
  out += fmt::format("basalt_http_rejected_total{{reason=\"rate\"}} {}\n", server.rejectedRate);
  out += fmt::format("basalt_http_rejected_total{{reason=\"auth\"}} {}\n", server.rejectedAuth);
  out += fmt::format("basalt_http_rejected_total{{reason=\"size\"}} {}\n", server.rejectedSize);
  out += fmt::format("basalt_http_rejected_total{{reason=\"connections\"}} {}\n", server.rejectedConnections);
  out += fmt::format("basalt_http_rejected_total{{reason=\"timeout\"}} {}\n", server.rejectedTimeout);
  out += fmt::format("basalt_http_rejected_total{{reason=\"head\"}} {}\n", server.rejectedHead);
  out += fmt::format("basalt_http_rejected_total{{reason=\"evicted\"}} {}\n", server.evicted);
  if (const std::optional<ProcessFigures>& p = s.process) {
    // The names and meanings of Prometheus' client libraries, so that the usual dashboards work.
    metric("process_cpu_seconds_total", "counter", "Total user and system CPU time spent in seconds.");
    out += fmt::format("process_cpu_seconds_total {}\n", number(p->cpuSeconds));
    metric("process_resident_memory_bytes", "gauge", "Resident memory size in bytes.");
    out += fmt::format("process_resident_memory_bytes {}\n", p->residentBytes);
    metric("process_virtual_memory_bytes", "gauge", "Virtual memory size in bytes.");
    out += fmt::format("process_virtual_memory_bytes {}\n", p->virtualBytes);
    metric("process_open_fds", "gauge", "Number of open file descriptors.");
    out += fmt::format("process_open_fds {}\n", p->openFds);
    metric("process_max_fds", "gauge", "Maximum number of open file descriptors.");
    out += fmt::format("process_max_fds {}\n", p->maxFds);
    if (p->startSeconds) {
      metric("process_start_time_seconds", "gauge", "Start time of the process since unix epoch in seconds.");
      out += fmt::format("process_start_time_seconds {:.2f}\n", *p->startSeconds);
    }
  }
  return out;
}

Image scaleDown(const Image& image, std::uint32_t width) {
  if (width == 0 || width >= image.width || image.type != ChannelType::kU8) return image;
  const std::uint32_t height =
      std::max<std::uint32_t>(1, static_cast<std::uint32_t>(std::uint64_t{image.height} * width / image.width));
  Image out = Image::make(width, height, image.channels);
  for (std::uint32_t y = 0; y < height; ++y) {
    const std::uint32_t y0 = static_cast<std::uint32_t>(std::uint64_t{y} * image.height / height);
    const std::uint32_t y1 = std::max(y0 + 1, static_cast<std::uint32_t>(std::uint64_t{y + 1} * image.height / height));
    for (std::uint32_t x = 0; x < width; ++x) {
      const std::uint32_t x0 = static_cast<std::uint32_t>(std::uint64_t{x} * image.width / width);
      const std::uint32_t x1 = std::max(x0 + 1, static_cast<std::uint32_t>(std::uint64_t{x + 1} * image.width / width));
      for (std::uint32_t c = 0; c < image.channels; ++c) {
        std::uint32_t sum = 0;
        for (std::uint32_t yy = y0; yy < y1; ++yy) {
          for (std::uint32_t xx = x0; xx < x1; ++xx) sum += image.at(xx, yy, c);
        }
        out.pixels[(std::size_t{y} * width + x) * image.channels + c] =
            static_cast<std::uint8_t>(sum / ((y1 - y0) * (x1 - x0)));
      }
    }
  }
  return out;
}

std::string_view statusPageHtml() {
  return R"html(<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>Basalt status</title>
<style>
  :root { color-scheme: dark; }
  body { margin: 0; font: 15px/1.4 system-ui, sans-serif; background: #15171c; color: #e8e8e8; }
  header { padding: 12px 16px; background: #20242c; display: flex; align-items: center; gap: 12px; flex-wrap: wrap; }
  header h1 { font-size: 20px; margin: 0; flex: 1; min-width: 8em; }
  #version { color: #9fb3c8; font-size: 13px; }
  #state { padding: 4px 10px; border-radius: 12px; font-weight: 600; background: #555; }
  #state.ok { background: #1f8a3a; }
  #state.degraded { background: #c27c0e; }
  #state.down { background: #b3261e; }
  .notice { margin: 12px 16px 0; padding: 10px 12px; border-radius: 8px; background: #3a2e12; color: #f3d49b;
            border: 1px solid #6b531c; }
  #problems { white-space: pre-line; margin: 12px 16px 0; padding: 8px 10px; border-left: 4px solid #c27c0e; background: #3a2a0a; }
  main { padding: 12px 16px; display: grid; gap: 14px; grid-template-columns: minmax(0, 1fr); align-items: start; }
  @media (min-width: 900px) { main { grid-template-columns: repeat(2, minmax(0, 1fr)); } .wide { grid-column: 1 / -1; } }
  @media (min-width: 1400px) { main { grid-template-columns: repeat(3, minmax(0, 1fr)); } }
  section { background: #1d2027; border-radius: 10px; padding: 12px; min-width: 0; }
  h2 { font-size: 15px; margin: 0 0 8px; color: #9fb3c8; text-transform: uppercase; letter-spacing: .05em; }
  #thumb { width: 100%; max-width: 480px; background: #000; border-radius: 6px; display: block; }
  #thumb[hidden] { display: none; }
  table { width: 100%; border-collapse: collapse; }
  td { padding: 4px 6px; border-top: 1px solid #2c313b; vertical-align: top; overflow-wrap: break-word; }
  td.nowrap { white-space: nowrap; }
  .device { border-top: 1px solid #2c313b; padding: 6px 2px; }
  .device .head { display: flex; flex-wrap: wrap; gap: 4px 10px; align-items: baseline; }
  .device .name { font-weight: 600; }
  .device .since { color: #9aa3ad; margin-left: auto; white-space: nowrap; }
  .device .message { color: #c3c9d2; font-size: 14px; overflow-wrap: break-word; }
  .device button { padding: 2px 10px; font-size: 13px; }
  .live, .playing, .ok { color: #5fd17a; } .absent, .lost, .waiting, .warning { color: #f0a030; }
  .error, .fatal { color: #ff8a80; } .idle, .muted { color: #9aa3ad; }
  dl.facts { display: grid; grid-template-columns: max-content minmax(0, 1fr); gap: 4px 12px; margin: 0; }
  dl.facts dt { color: #9fb3c8; } dl.facts dd { margin: 0; overflow-wrap: break-word; min-width: 0; }
  #log { font: 12px/1.35 ui-monospace, monospace; white-space: pre-wrap; max-height: 240px; overflow: auto; }
  .figures { display: grid; grid-template-columns: repeat(auto-fit, minmax(110px, 1fr)); gap: 8px; }
  .figure b { display: block; font-size: 22px; }
  form { display: flex; flex-wrap: wrap; gap: 8px; }
  input, button { font: inherit; padding: 8px 12px; border-radius: 6px; border: 1px solid #3a404c; background: #262a33; color: inherit; }
  td button { padding: 2px 10px; font-size: 13px; }
  button:disabled { opacity: .45; }
  a { color: #8ab4f8; }
  #answer { min-height: 1.4em; }
</style>
</head>
<body>
<header><h1 id="show">Basalt</h1><span id="version"></span><span id="state">…</span></header>
<p class="notice" id="controls-off" hidden>Controls are off: this show has no token. Set <code>token_file</code>
  under <code>[status]</code> in show.toml to use the buttons on this page.</p>
<p class="notice" id="unreachable" hidden>Basalt does not answer: the figures below are the last it gave.</p>
<p id="problems" hidden></p>
<main>
  <section><h2>On screen</h2><img id="thumb" alt="the frame on screen now" hidden>
    <p id="snapshot-off" hidden>The snapshot is off in this show ([status] snapshot = false).</p>
    <p id="item"></p></section>
  <section><h2>This machine</h2><dl class="facts">
    <dt>Basalt</dt><dd id="build">–</dd>
    <dt>Host name</dt><dd id="hostname">–</dd>
    <dt>Addresses</dt><dd id="addresses">–</dd>
    <dt>Up</dt><dd id="uptimes">–</dd>
    <dt>Disk</dt><dd id="disk">–</dd>
    <dt>Memory</dt><dd id="memory">–</dd>
    <dt>CPU temperature</dt><dd id="temperature">–</dd></dl></section>
  <section><h2>Devices</h2><div id="devices"></div></section>
  <section><h2>Frames</h2><div class="figures">
    <div class="figure"><b id="fps">–</b>frames per second</div>
    <div class="figure"><b id="p99">–</b>ms frame time (99%)</div>
    <div class="figure"><b id="late">–</b>late frames</div>
    <div class="figure"><b id="dropped">–</b>dropped frames</div>
    <div class="figure"><b id="uptime">–</b>up</div></div></section>
  <section><h2>Last errors</h2><table id="errors"></table></section>
  <section><h2>Streams</h2><table id="streams"></table></section>
  <section><h2>Frame lock</h2><dl class="facts" id="lock"></dl></section>
  <section class="wide"><h2>Log</h2>
    <p><a id="log-download" href="/log.txt" download="basalt.log">Download the log</a>
      <span class="muted">(the records Basalt keeps; the journal has the rest: journalctl -u basalt)</span></p>
    <div id="log"></div></section>
  <section><h2>Controls</h2>
    <form id="controls" onsubmit="return false">
      <input id="token" type="password" placeholder="token" autocomplete="current-password">
      <button data-control="previous">Previous</button><button data-control="next">Next</button>
      <button data-control="reload">Reload</button>
    </form><p id="answer"></p></section>
</main>
<script>
"use strict";
const $ = (id) => document.getElementById(id);
let controlsOn = false;
let snapshotOn = false;
function text(s) { return document.createTextNode(s); }
function cell(tr, value, cls) { const td = tr.insertCell(); td.append(value instanceof Node ? value : text(value)); if (cls) td.className = cls; return td; }
function rows(table, items, cells) {
  table.replaceChildren();
  if (!items.length) { cell(table.insertRow(), "none", "muted"); return; }
  for (const item of items) { const tr = table.insertRow(); for (const [value, cls] of cells(item)) cell(tr, value, cls); }
}
function facts(dl, pairs) {
  dl.replaceChildren();
  for (const [name, value] of pairs) { const dt = document.createElement("dt"); dt.textContent = name; const dd = document.createElement("dd"); dd.textContent = value; dl.append(dt, dd); }
}
function duration(s) { return s < 120 ? Math.round(s) + " s" : s < 7200 ? Math.round(s / 60) + " min" : s < 172800 ? (s / 3600).toFixed(1) + " h" : (s / 86400).toFixed(1) + " days"; }
function since(iso) { return duration(Math.max(0, (Date.now() - Date.parse(iso)) / 1000)); }
function bytes(n) { const units = ["B", "kB", "MB", "GB", "TB"]; let i = 0; while (n >= 1000 && i < units.length - 1) { n /= 1000; ++i; } return (i ? n.toFixed(1) : n) + " " + units[i]; }
function clock(iso) { return new Date(iso).toLocaleTimeString(); }
function span(value, cls) { const e = document.createElement("span"); e.textContent = value; e.className = cls; return e; }
function devices(list, items) {
  list.replaceChildren();
  if (!items.length) { list.append(span("none", "muted")); return; }
  for (const d of items) {
    const row = document.createElement("div"); row.className = "device";
    const head = document.createElement("div"); head.className = "head";
    head.append(span(d.name, "name"), span(d.state, d.state), span("for " + since(d.since), "since"), restartButton(d.name));
    const message = document.createElement("div"); message.className = "message";
    message.textContent = d.backend + (d.message ? " · " + d.message : "");
    row.append(head, message);
    list.append(row);
  }
}
function restartButton(name) {
  const b = document.createElement("button");
  b.textContent = "Restart"; b.dataset.device = name; b.disabled = !controlsOn;
  b.title = controlsOn ? "close and open " + name + " again" : "controls are off: this show has no token";
  return b;
}
async function control(path, what) {
  localStorage.setItem("basalt-token", $("token").value);
  const r = await fetch(path, {method: "POST", headers: {"Authorization": "Bearer " + $("token").value}});
  const a = await r.json().catch(() => ({message: r.statusText}));
  $("answer").textContent = what + ": " + r.status + ": " + a.message;
  refresh();
}
async function refresh() {
  let h;
  try {
    const r = await fetch("/health", {cache: "no-store"});
    h = await r.json();
  } catch (e) {
    $("state").textContent = "unreachable"; $("state").className = "down"; $("unreachable").hidden = false;
    return;
  }
  $("unreachable").hidden = true;
  const server = h.server || {controls: true, snapshot: true};
  controlsOn = server.controls;
  $("controls-off").hidden = controlsOn;
  for (const b of document.querySelectorAll("#controls button")) b.disabled = !controlsOn;
  $("show").textContent = h.show.name || "Basalt";
  $("version").textContent = "Basalt " + h.build.version;
  $("state").textContent = h.state; $("state").className = h.state;
  $("problems").hidden = !h.problems.length; $("problems").textContent = h.problems.join("\n");
  $("item").textContent = h.show.description + (h.show.next_schedule_change ? " · schedule changes " + new Date(h.show.next_schedule_change).toLocaleString() : "");
  $("fps").textContent = h.frames.per_second === null ? "–" : h.frames.per_second.toFixed(1);
  $("p99").textContent = h.frames.frame_time_ms.p99 === null ? "–" : h.frames.frame_time_ms.p99.toFixed(1);
  $("late").textContent = h.frames.late;
  $("dropped").textContent = h.frames.dropped;
  $("uptime").textContent = duration(h.uptime_seconds);
  devices($("devices"), h.devices);
  rows($("streams"), h.streams, (s) => [[s.name, "nowrap"], [s.state, s.state + " nowrap"], [s.message]]);
  rows($("errors"), h.last_errors.slice().reverse(), (e) => [[clock(e.time), "nowrap"], [e.level, e.level + " nowrap"], [e.category + ": " + e.message]]);
  const l = h.lock;
  facts($("lock"), !l ? [["role", "not frame-locked (no [lock] in show.toml)"]] : l.role === "leader"
    ? [["role", "leader '" + l.node + "'"], ["followers", l.followers + " of " + l.followers_known], ["barrier time-outs", l.barrier_timeouts], ["wait for answers", l.barrier_wait_ms.p50 + " ms (max " + l.barrier_wait_ms.max + ")"], ["followers dropped / rejoined", l.followers_dropped + " / " + l.followers_rejoined]]
    : [["role", "follower '" + l.node + "'"], ["leader", l.leader_present ? "present" : "lost" + (l.holding ? ", holding frame " + l.held_frame + " for " + duration(l.holding_seconds) : "")], ["skipped / presents missed", l.skipped + " / " + l.presents_missed], ["clock offset", l.clock_offset_us + " µs"], ["delay", l.delay_ms.p50 + " ms (max " + l.delay_ms.max + ")"], ["leader lost / returned", l.leader_lost + " / " + l.leader_returned]]);
  $("build").textContent = h.build.version + ", revision " + h.build.revision + " (" + h.build.build + ")";
  const m = h.machine;
  if (m) {
    $("hostname").textContent = m.hostname;
    $("addresses").textContent = m.addresses.length ? m.addresses.map((a) => a.address + " (" + a.interface + ")").join(", ") : "none but loopback";
    $("uptimes").textContent = "Basalt " + duration(h.uptime_seconds) + " · machine " + duration(m.uptime_seconds);
    $("disk").textContent = m.disks.length ? m.disks.map((d) => d.name + ": " + (d.error ? "unreadable (" + d.error + ")" : bytes(d.free_bytes) + " free of " + bytes(d.total_bytes)) + " (" + d.path + ")").join("; ") : "no folder to watch";
    $("memory").textContent = bytes(m.memory.available_bytes) + " available of " + bytes(m.memory.total_bytes) + (h.process ? " · Basalt uses " + bytes(h.process.resident_bytes) : "");
    $("temperature").textContent = m.cpu_temperature ? m.cpu_temperature.celsius.toFixed(1) + " °C (" + m.cpu_temperature.sensor + ")" : "no sensor";
  }
  $("log").textContent = h.log_tail.join("\n");
  snapshotOn = server.snapshot;
  $("thumb").hidden = !snapshotOn; $("snapshot-off").hidden = snapshotOn;
  if (snapshotOn && !$("thumb").getAttribute("src")) refreshThumb();
}
function refreshThumb() { if (snapshotOn) $("thumb").src = "/snapshot.png?w=480&t=" + Date.now(); }
$("token").value = localStorage.getItem("basalt-token") || "";
for (const b of document.querySelectorAll("[data-control]")) {
  b.addEventListener("click", () => control("/control/" + b.dataset.control, b.dataset.control));
}
$("devices").addEventListener("click", (e) => {
  const b = e.target.closest("button[data-device]");
  if (b) control("/control/restart-device?device=" + encodeURIComponent(b.dataset.device), "restart " + b.dataset.device);
});
refresh();
setInterval(refresh, 2000);
setInterval(refreshThumb, 5000);
</script>
</body>
</html>
)html";
}

}  // namespace basalt::kiosk
