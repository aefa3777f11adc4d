#include "kiosk/status/status_report.h"

#include <algorithm>
#include <chrono>

#include <fmt/format.h>

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

std::string jsonString(std::string_view text) {
  std::string out = "\"";
  for (const char c : text) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          out += fmt::format("\\u{:04x}", static_cast<unsigned>(c));
        } else {
          out += c;
        }
    }
  }
  out += '"';
  return out;
}

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
  std::string out = "{\n";
  out += fmt::format("  \"state\": {},\n", jsonString(overallState(s)));
  out += fmt::format("  \"time\": {},\n", jsonString(isoTime(s.now)));
  out += fmt::format("  \"uptime_seconds\": {:.3f},\n", std::chrono::duration<double>(s.now - s.startedAt).count());
  const ShowStatus& sh = s.show;
  out += "  \"show\": {\n";
  out += fmt::format("    \"name\": {},\n    \"manifest\": {},\n    \"output\": {},\n", jsonString(sh.name),
                     jsonString(sh.manifest), jsonString(sh.output));
  out += fmt::format("    \"open\": {},\n    \"mode\": {},\n    \"display\": {},\n", sh.open ? "true" : "false",
                     jsonString(sh.mode), jsonString(sh.display));
  out += fmt::format("    \"item\": {},\n    \"index\": {},\n    \"count\": {},\n", jsonString(sh.item), sh.index,
                     sh.count);
  out += fmt::format("    \"description\": {},\n", jsonString(sh.description));
  out += fmt::format("    \"next_schedule_change\": {}\n  }},\n",
                     sh.nextScheduleChange ? jsonString(isoTime(*sh.nextScheduleChange)) : std::string("null"));
  out += "  \"frames\": {\n";
  out += fmt::format("    \"total\": {},\n    \"per_second\": {:.2f},\n", f.frames, f.framesPerSecond);
  out += fmt::format("    \"frame_time_ms\": {{\"p50\": {:.3f}, \"p90\": {:.3f}, \"p99\": {:.3f}, \"max\": {:.3f}}},\n",
                     f.intervalP50 * 1e3, f.intervalP90 * 1e3, f.intervalP99 * 1e3, f.intervalMax * 1e3);
  out += fmt::format("    \"work_ms\": {{\"p50\": {:.3f}, \"p90\": {:.3f}, \"p99\": {:.3f}, \"max\": {:.3f}}},\n",
                     f.workP50 * 1e3, f.workP90 * 1e3, f.workP99 * 1e3, f.workMax * 1e3);
  out += fmt::format("    \"window\": {},\n    \"late\": {},\n    \"dropped\": {},\n", f.window, f.lateFrames,
                     f.droppedFrames);
  out += fmt::format("    \"missed_at_reload\": {},\n    \"input_events_dropped\": {}\n  }},\n", f.missedAtReload,
                     f.inputDropped);
  // LAVA's performance meter (manual §9): the last sampled frame's counts, rates over the sample.
  const runtime::PerformanceMeter& m = s.performance;
  out += fmt::format(
      "  \"performance\": {{\"triangles\": {}, \"lines\": {}, \"points\": {}, \"parts\": {}, \"facets\": {}, "
      "\"fps\": {:.2f}, \"primitives_per_second\": {:.0f}, \"sample_seconds\": {:.1f}, \"samples\": {}}},\n",
      m.triangles, m.lines, m.points, m.parts, m.facets, m.framesPerSecond, m.primitivesPerSecond,
      m.samplePeriodSeconds, m.updates);
  if (const std::optional<FrameLockFigures>& l = s.lock) {
    out += fmt::format(
        "  \"lock\": {{\"role\": {}, \"node\": {}, \"followers\": {}, \"followers_known\": {}, "
        "\"barrier_timeouts\": {}, \"followers_dropped\": {}, \"followers_rejoined\": {}, \"late_answers\": {}, "
        "\"barrier_wait_ms\": {{\"p50\": {:.3f}, \"max\": {:.3f}}}, \"leader_present\": {}, \"leader_lost\": {}, "
        "\"frames_drawn\": {}, \"last_frame\": {}, \"skipped\": {}, \"presents_missed\": {}, \"skew_frames_max\": {}, "
        "\"clock_offset_us\": {}, \"delay_ms\": {{\"p50\": {:.3f}, \"max\": {:.3f}}}, \"malformed\": {}, "
        "\"holding\": {}, \"holding_seconds\": {:.1f}, \"held_frame\": {}, \"leader_returned\": {}, "
        "\"leader_restarts\": {}, "
        "\"watchdog_pings_holding\": {}, \"programme_changes\": {}, \"commands_applied\": {}, "
        "\"commands_resent\": {}, \"commands_lost\": {}, \"movie_frames_corrected\": {}, "
        "\"movie_frames_late\": {}}},\n",
        jsonString(l->leader ? "leader" : "follower"), jsonString(l->node), l->followers, l->followersKnown,
        l->barrierTimeouts, l->followersDropped, l->followersRejoined, l->lateAnswers, l->barrierWaitP50Ms,
        l->barrierWaitMaxMs, l->leaderPresent ? "true" : "false", l->leaderLost, l->framesDrawn, l->lastFrame,
        l->skipped, l->presentsMissed, l->maxSkewFrames, l->leader ? l->maxClockOffsetUs : l->clockOffsetUs,
        l->delayP50Ms, l->delayMaxMs, l->malformed, l->holding ? "true" : "false", l->holdingSeconds, l->heldFrame,
        l->leaderReturned, l->leaderRestarts, l->watchdogPingsHolding, l->programmeChanges, l->commandsApplied,
        l->commandsResent, l->commandsLost, l->movieFramesCorrected, l->movieFramesLate);
  }
  out += "  \"devices\": [";
  for (std::size_t i = 0; i < s.devices.size(); ++i) {
    const DeviceStatus& d = s.devices[i];
    out += fmt::format(
        "{}\n    {{\"name\": {}, \"kind\": {}, \"backend\": {}, \"state\": {}, \"since\": {}, \"message\": {}}}",
        i ? "," : "", jsonString(d.name), jsonString(d.kind), jsonString(d.backend), jsonString(d.state),
        jsonString(isoTime(d.since)), jsonString(d.message));
  }
  out += s.devices.empty() ? "],\n" : "\n  ],\n";
  out += "  \"streams\": [";
  for (std::size_t i = 0; i < s.streams.size(); ++i) {
    const StreamStatus& st = s.streams[i];
    out += fmt::format("{}\n    {{\"name\": {}, \"kind\": {}, \"state\": {}, \"since\": {}, \"message\": {}}}",
                       i ? "," : "", jsonString(st.name), jsonString(st.kind), jsonString(st.state),
                       jsonString(isoTime(st.since)), jsonString(st.message));
  }
  out += s.streams.empty() ? "],\n" : "\n  ],\n";
  out += fmt::format("  \"reloads\": {{\"total\": {}, \"failed\": {}, \"last\": {}}},\n", s.reloads, s.reloadFailures,
                     jsonString(s.lastReload));
  out += "  \"problems\": [";
  for (std::size_t i = 0; i < s.problems.size(); ++i) {
    out += fmt::format("{}\n    {}", i ? "," : "", jsonString(s.problems[i]));
  }
  out += s.problems.empty() ? "],\n" : "\n  ],\n";
  out += fmt::format("  \"errors_logged\": {},\n", s.errorsLogged);
  out += "  \"last_errors\": [";
  for (std::size_t i = 0; i < s.lastErrors.size(); ++i) {
    const log::Record& r = s.lastErrors[i];
    out += fmt::format("{}\n    {{\"time\": {}, \"level\": {}, \"category\": {}, \"message\": {}}}", i ? "," : "",
                       jsonString(isoTime(r.wallTime)), jsonString(log::levelName(r.level)), jsonString(r.category),
                       jsonString(r.message));
  }
  out += s.lastErrors.empty() ? "],\n" : "\n  ],\n";
  out += "  \"log_tail\": [";
  const std::size_t first = s.logTail.size() > 30 ? s.logTail.size() - 30 : 0;
  for (std::size_t i = first; i < s.logTail.size(); ++i) {
    const log::Record& r = s.logTail[i];
    out += fmt::format(
        "{}\n    {}", i > first ? "," : "",
        jsonString(fmt::format("{} {} {}: {}", isoTime(r.wallTime), log::levelName(r.level), r.category, r.message)));
  }
  out += s.logTail.empty() ? "]\n" : "\n  ]\n";
  out += "}\n";
  return out;
}

std::string metricsText(const StatusSnapshot& s, const ServerCounters& server) {
  const FrameFigures& f = s.frames;
  std::string out;
  const auto metric = [&out](std::string_view name, std::string_view type, std::string_view help) {
    out += fmt::format("# HELP {} {}\n# TYPE {} {}\n", name, help, name, type);
  };
  metric("basalt_up", "gauge", "1 while the show runs; 0.5 when degraded (a device or stream is not live).");
  out += fmt::format("basalt_up {}\n", overallState(s) == "ok" ? "1" : "0.5");
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
  metric("basalt_frame_interval_seconds", "summary", "Time from one present to the next, recent frames.");
  for (const auto& [q, v] : {std::pair{"0.5", f.intervalP50}, {"0.9", f.intervalP90}, {"0.99", f.intervalP99}}) {
    out += fmt::format("basalt_frame_interval_seconds{{quantile=\"{}\"}} {:.6f}\n", q, v);
  }
  out += fmt::format("basalt_frame_interval_seconds_count {}\n", f.window);
  metric("basalt_frame_work_seconds", "summary", "The frame loop's own work per frame, recent frames.");
  for (const auto& [q, v] : {std::pair{"0.5", f.workP50}, {"0.9", f.workP90}, {"0.99", f.workP99}}) {
    out += fmt::format("basalt_frame_work_seconds{{quantile=\"{}\"}} {:.6f}\n", q, v);
  }
  out += fmt::format("basalt_frame_work_seconds_sum {:.6f}\n", f.workMean * static_cast<double>(f.window));
  out += fmt::format("basalt_frame_work_seconds_count {}\n", f.window);
  metric("basalt_frame_work_cpu_seconds", "summary",
         "The frame loop thread's CPU time per frame (its work without preemption), recent frames.");
  out += fmt::format("basalt_frame_work_cpu_seconds_sum {:.6f}\n", f.cpuMean * static_cast<double>(f.window));
  out += fmt::format("basalt_frame_work_cpu_seconds_count {}\n", f.window);
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
  metric("basalt_device_up", "gauge", "1 while the device is live.");
  for (const DeviceStatus& d : s.devices) {
    out += fmt::format("basalt_device_up{{device=\"{}\",kind=\"{}\",backend=\"{}\",state=\"{}\"}} {}\n",
                       promLabel(d.name), d.kind, d.backend, d.state, d.state == "live" ? 1 : 0);
  }
  metric("basalt_device_state_since_seconds", "gauge", "When the device entered its state, seconds since 1970.");
  for (const DeviceStatus& d : s.devices) {
    out += fmt::format("basalt_device_state_since_seconds{{device=\"{}\"}} {:.3f}\n", promLabel(d.name),
                       unixSeconds(d.since));
  }
  metric("basalt_stream_up", "gauge", "1 while the stream plays.");
  for (const StreamStatus& st : s.streams) {
    out += fmt::format("basalt_stream_up{{stream=\"{}\",kind=\"{}\",state=\"{}\"}} {}\n", promLabel(st.name), st.kind,
                       st.state, st.state == "playing" ? 1 : 0);
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
      lockMetric("basalt_lock_barrier_wait_ms", "gauge", "The leader's median wait for the answers (ms).",
                 fmt::format("{:.3f}", l->barrierWaitP50Ms));
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
      lockMetric("basalt_lock_clock_offset_us", "gauge", "The shared clock minus this node's clock (us).",
                 l->clockOffsetUs);
    }
    lockMetric("basalt_lock_malformed_total", "counter", "Frame-lock messages rejected.", l->malformed);
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
  body { margin: 0; font: 16px/1.4 system-ui, sans-serif; background: #15171c; color: #e8e8e8; }
  header { padding: 12px 16px; background: #20242c; display: flex; align-items: center; gap: 12px; }
  header h1 { font-size: 20px; margin: 0; flex: 1; }
  #state { padding: 4px 10px; border-radius: 12px; font-weight: 600; background: #555; }
  #state.ok { background: #1f8a3a; }
  #state.degraded { background: #c27c0e; }
  #state.down { background: #b3261e; }
  #problems { white-space: pre-line; padding: 8px 10px; border-left: 4px solid #c27c0e; background: #3a2a0a; }
  main { padding: 12px 16px; display: grid; gap: 14px; }
  section { background: #1d2027; border-radius: 10px; padding: 12px; }
  h2 { font-size: 15px; margin: 0 0 8px; color: #9fb3c8; text-transform: uppercase; letter-spacing: .05em; }
  #thumb { width: 100%; max-width: 480px; background: #000; border-radius: 6px; display: block; }
  table { width: 100%; border-collapse: collapse; }
  td { padding: 4px 6px; border-top: 1px solid #2c313b; vertical-align: top; }
  .live, .playing { color: #5fd17a; } .absent, .lost, .waiting { color: #f0a030; }
  #log { font: 12px/1.35 ui-monospace, monospace; white-space: pre-wrap; max-height: 240px; overflow: auto; }
  .figures { display: grid; grid-template-columns: repeat(auto-fit, minmax(120px, 1fr)); gap: 8px; }
  .figure b { display: block; font-size: 22px; }
  form { display: flex; flex-wrap: wrap; gap: 8px; }
  input, button { font: inherit; padding: 8px 12px; border-radius: 6px; border: 1px solid #3a404c; background: #262a33; color: inherit; }
  #answer { min-height: 1.4em; }
</style>
</head>
<body>
<header><h1 id="show">Basalt</h1><span id="state">…</span></header>
<p id="problems" hidden></p>
<main>
  <section><h2>On screen</h2><img id="thumb" alt="the frame on screen now" src="/snapshot.png?w=480">
    <p id="item"></p></section>
  <section><h2>Frames</h2><div class="figures">
    <div class="figure"><b id="fps">–</b>frames per second</div>
    <div class="figure"><b id="p99">–</b>ms frame time (99%)</div>
    <div class="figure"><b id="late">–</b>late frames</div>
    <div class="figure"><b id="uptime">–</b>up</div></div></section>
  <section><h2>Devices</h2><table id="devices"></table></section>
  <section><h2>Streams</h2><table id="streams"></table></section>
  <section><h2>Log</h2><div id="log"></div></section>
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
function text(s) { return document.createTextNode(s); }
function rows(table, items, cells) {
  table.replaceChildren();
  if (!items.length) { const tr = table.insertRow(); tr.insertCell().append(text("none")); return; }
  for (const item of items) {
    const tr = table.insertRow();
    for (const [value, cls] of cells(item)) { const td = tr.insertCell(); td.append(text(value)); if (cls) td.className = cls; }
  }
}
function since(iso) { const s = Math.max(0, (Date.now() - Date.parse(iso)) / 1000); return s < 120 ? Math.round(s) + " s" : s < 7200 ? Math.round(s / 60) + " min" : Math.round(s / 3600) + " h"; }
function duration(s) { return s < 120 ? Math.round(s) + " s" : s < 7200 ? Math.round(s / 60) + " min" : (s / 3600).toFixed(1) + " h"; }
async function refresh() {
  try {
    const r = await fetch("/health", {cache: "no-store"});
    const h = await r.json();
    $("show").textContent = h.show.name || "Basalt";
    $("state").textContent = h.state; $("state").className = h.state;
    $("problems").hidden = !h.problems.length; $("problems").textContent = h.problems.join("\n");
    $("item").textContent = h.show.description + (h.show.next_schedule_change ? " · schedule changes " + new Date(h.show.next_schedule_change).toLocaleString() : "");
    $("fps").textContent = h.frames.per_second.toFixed(1);
    $("p99").textContent = h.frames.frame_time_ms.p99.toFixed(1);
    $("late").textContent = h.frames.late;
    $("uptime").textContent = duration(h.uptime_seconds);
    rows($("devices"), h.devices, (d) => [[d.name], [d.state, d.state], [d.backend + (d.message ? " · " + d.message : "")], ["for " + since(d.since)]]);
    rows($("streams"), h.streams, (s) => [[s.name], [s.state, s.state], [s.message]]);
    $("log").textContent = h.log_tail.join("\n");
  } catch (e) {
    $("state").textContent = "unreachable"; $("state").className = "down";
  }
}
function refreshThumb() { $("thumb").src = "/snapshot.png?w=480&t=" + Date.now(); }
$("token").value = localStorage.getItem("basalt-token") || "";
for (const b of document.querySelectorAll("[data-control]")) {
  b.addEventListener("click", async () => {
    localStorage.setItem("basalt-token", $("token").value);
    const r = await fetch("/control/" + b.dataset.control, {method: "POST", headers: {"Authorization": "Bearer " + $("token").value}});
    const a = await r.json().catch(() => ({message: r.statusText}));
    $("answer").textContent = r.status + ": " + a.message;
    refresh();
  });
}
refresh();
setInterval(refresh, 2000);
setInterval(refreshThumb, 5000);
</script>
</body>
</html>
)html";
}

}  // namespace basalt::kiosk
