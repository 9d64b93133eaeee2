// A program outside rsg that reads through a view, built against the installed package on whichever
// Fast DDS rsg was built with (2.x or 3.x): the Fast DDS names that differ between the two come from
// the installed rsg/dds/fastdds.hpp. One participant, a view_joints reader (reliable: the logger QoS)
// and a writer of RobotState; of a sample carrying group 2 and one without it, the view gets exactly
// the first, exact. Exits 0 then.
//
//   view_consumer PROFILES_DIR DOMAIN
#include <cstdio>
#include <cstdlib>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <thread>

#include "rsg/dds/fastdds.hpp"
#include "rsg/dds/participant.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/dds/robot_state.hpp"
#include "rsg/dds/views.hpp"
#include "rsg/wire/state_values.hpp"

namespace fdds = eprosima::fastdds::dds;

int main(int argc, char** argv) {
  if (argc != 3) return std::puts("usage: view_consumer PROFILES_DIR DOMAIN"), 2;
  rsg::dds::load_profiles(argv[1]);
  rsg::dds::Participant participant(std::atoi(argv[2]), "rsg_participant");
  fdds::Topic& topic = *participant.robot_state_topic("robot_state");
  rsg::dds::ViewReader joints(*participant.subscriber(), topic, "view_joints",
                              rsg::dds::kLoggerReaderProfile);

  fdds::Publisher& publisher = *participant.publisher();
  fdds::DataWriterQos qos = publisher.get_default_datawriter_qos();
  qos.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
  qos.history().kind = fdds::KEEP_ALL_HISTORY_QOS;
  fdds::DataWriter* writer = publisher.create_datawriter(&topic, qos);
  if (writer == nullptr) return std::puts("no writer"), 1;
  fdds::PublicationMatchedStatus matched;
  for (int i = 0; i < 500 && (writer->get_publication_matched_status(matched) != rsg::dds::kOk ||
                              matched.current_count < 1);
       ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  if (matched.current_count < 1) return std::puts("the view reader did not match"), 1;

  rsg::RobotState sample;
  for (const char* fields : {"q,dq,time", "O_T_EE,time"}) {  // group 2 (q) in the first only
    rsg::wire::StateValues values;
    const auto selection = rsg::wire::parse_field_list(fields);
    if (!selection) return std::printf("selection %s: %s\n", fields, selection.error().c_str()), 1;
    values.selection = *selection;
    for (double& q : values.doubles(rsg::wire::Field::q)) q = 0.75;
    rsg::dds::to_sample(values, sample);
    if (!rsg::dds::succeeded(writer->write(&sample))) return std::puts("write failed"), 1;
  }
  if (writer->wait_for_acknowledgments(rsg::dds::Duration(10, 0)) != rsg::dds::kOk)
    return std::puts("the view reader did not acknowledge"), 1;

  int taken = 0;
  double q0 = 0;
  fdds::SampleInfo info;
  while (joints->take_next_sample(&sample, &info) == rsg::dds::kOk)
    if (info.valid_data) ++taken, q0 = sample.q()[0];
  publisher.delete_datawriter(writer);
  if (taken != 1 || q0 != 0.75) return std::printf("view_joints took %d samples, q[0]=%g\n", taken, q0), 1;
  std::printf("view_consumer: view_joints took exactly the sample carrying group 2 (Fast DDS %d)\n",
              RSG_FASTDDS_MAJOR);
  return 0;
}
