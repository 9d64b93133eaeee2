// The measuring end of the DDS scenarios: a RobotState reader that stamps each sample on arrival.
//
// Samples are taken in on_data_available, on the Fast DDS thread that delivered them (the
// transport's receive thread, or data-sharing's listener), with loans: the receive time is read
// as soon as take() returns, and a data-sharing reader reads the stamp in the writer's shared
// memory without copying the sample. take() itself is part of what a reader pays (a RELIABLE
// data-sharing reader of Fast DDS 2.9 sends an ACKNACK inside it), so an optional second log
// records, for the same samples, the time the listener was entered (before take).
#pragma once

#include <chrono>
#include <fastdds/dds/core/condition/GuardCondition.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <string>
#include <thread>

#include "rsg/dds/participant.hpp"
#include "tests/bench/e2e/latency_log.hpp"

namespace rsg::bench {

class StateSubscriber : private eprosima::fastdds::dds::DataReaderListener {
 public:
  /// Creates the reader; `log` must outlive it. Samples are taken in the listener, or with
  /// `waitset` on a thread of this object's own that waits on a WaitSet (as rsg_echo does).
  /// `notified`, if given, gets each sample's time of entry into the listener (or of the
  /// WaitSet's wake-up), before take(). Throws std::runtime_error.
  StateSubscriber(dds::Participant& participant, const std::string& topic, const std::string& reader_profile,
                  LatencyLog& log, bool waitset = false, LatencyLog* notified = nullptr);
  ~StateSubscriber() override;
  StateSubscriber(const StateSubscriber&) = delete;
  StateSubscriber& operator=(const StateSubscriber&) = delete;

  /// Waits until a writer has matched; false on timeout.
  bool wait_for_writer(std::chrono::milliseconds timeout) const;
  /// Waits until `log` holds every frame or `timeout` passes; true when it holds every frame.
  bool wait_for_all(std::chrono::milliseconds timeout) const;

 private:
  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override;
  void take_all(eprosima::fastdds::dds::DataReader* reader, std::int64_t notified_ns);

  dds::Participant& participant_;
  LatencyLog& log_;
  LatencyLog* notified_;
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;
  eprosima::fastdds::dds::DataReader* reader_ = nullptr;
  eprosima::fastdds::dds::GuardCondition stop_;
  std::thread waiting_;  // WaitSet mode only
};

/// True when this process has a Fast DDS data-sharing segment mapped: a data-sharing reader maps
/// its writer's history (/dev/shm/fast_datasharing_*), a reader served by a transport never does.
bool maps_data_sharing_segment();

}  // namespace rsg::bench
