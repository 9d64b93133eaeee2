// rsg_bench_cyclone_reader DOMAIN TOPIC FRAMES OUT: the bench's Cyclone DDS reader (C API).
//
// Reliable, volatile, keep last 100, like the bench's Fast DDS reader; takes samples with loans in
// its data-available listener, on the thread that delivered them, reading the clock first. Logs
// "matched" once a writer matched; stops after FRAMES samples or on SIGTERM and then writes one
// "index sent_ns received_ns" line per sample to OUT, for rsg_bench_e2e to summarise.
#include <time.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include "tests/bench/floor/cyclone_topic.hpp"

namespace {

struct Arrival {
  std::int64_t index, sent_ns, received_ns;
};

std::atomic<bool> stop_requested{false};

struct Log {
  std::vector<Arrival> arrivals;  // reserved up front: the listener never allocates
  std::atomic<std::size_t> count{0};
};

std::int64_t monotonic_ns() {
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);
  return std::int64_t{now.tv_sec} * 1'000'000'000 + now.tv_nsec;
}

void on_data_available(dds_entity_t reader, void* arg) {
  const std::int64_t received_ns = monotonic_ns();
  Log& log = *static_cast<Log*>(arg);
  void* samples[16] = {};
  dds_sample_info_t infos[16];
  for (dds_return_t taken; (taken = dds_take(reader, samples, infos, 16, 16)) > 0;) {
    for (dds_return_t i = 0; i < taken; ++i) {
      if (!infos[i].valid_data) continue;
      const auto& sample = *static_cast<const rsg_RobotState*>(samples[i]);
      const std::size_t at = log.count.load(std::memory_order_relaxed);
      if (at == log.arrivals.size()) continue;
      log.arrivals[at] = {static_cast<std::int64_t>(sample.elbow_d[0]),
                          static_cast<std::int64_t>(sample.elbow_d[1]), received_ns};
      log.count.store(at + 1, std::memory_order_release);
    }
    dds_return_loan(reader, samples, taken);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::cerr << "usage: rsg_bench_cyclone_reader DOMAIN TOPIC FRAMES OUT\n";
    return 2;
  }
  std::signal(SIGTERM, [](int) { stop_requested = true; });
  using rsg::interop::Entity;
  using rsg::interop::Qos;
  Log log;
  log.arrivals.resize(std::stoul(argv[3]));
  try {
    const rsg::bench::CycloneTopic dds(argv[1], argv[2]);
    Qos qos;
    dds_qset_reliability(qos.get(), DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_history(qos.get(), DDS_HISTORY_KEEP_LAST, 100);
    dds_listener_t* listener = dds_create_listener(&log);
    dds_lset_data_available(listener, on_data_available);
    Entity reader(dds_create_reader(dds.participant.get(), dds.topic.get(), qos.get(), listener), "reader");
    dds_delete_listener(listener);

    for (dds_subscription_matched_status_t matched{}; matched.current_count == 0 && !stop_requested;
         dds_get_subscription_matched_status(reader.get(), &matched))
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    std::cerr << "matched" << std::endl;
    while (!stop_requested && log.count.load(std::memory_order_acquire) < log.arrivals.size())
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    dds_set_listener(reader.get(), nullptr);
  } catch (const std::exception& error) {
    std::cerr << "rsg_bench_cyclone_reader: " << error.what() << '\n';
    return 1;
  }
  std::ofstream out(argv[4]);
  for (std::size_t i = 0; i < log.count.load(); ++i)
    out << log.arrivals[i].index << ' ' << log.arrivals[i].sent_ns << ' ' << log.arrivals[i].received_ns
        << '\n';
  return out ? 0 : 1;
}
