// RAII owners of DDS entities that must go before their participant does (CONTRIBUTING.md,
// "Resources"): a gateway part that is stopped while the participant lives on deletes its
// publisher, writers, subscriber and reader itself. Each owner deletes its entity through the
// entity that created it; declare an owner after the owner of its parent, so that it goes first.
//
//   dds::OwnedPublisher publisher = dds::own(participant, participant.publisher());
//   dds::OwnedWriter writer = dds::own(*publisher, publisher->create_datawriter(...), "the status writer");
//
// Entities that live as long as their participant need no owner: dds::Participant deletes what it
// contains.
#pragma once

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <memory>
#include <string>
#include <string_view>

#include "rsg/dds/participant.hpp"
#include "rsg/error.hpp"

namespace rsg::dds {

namespace detail {

/// Deletes a Publisher and what it still contains.
struct DeletePublisher {
  eprosima::fastdds::dds::DomainParticipant* participant = nullptr;
  void operator()(eprosima::fastdds::dds::Publisher* publisher) const {
    publisher->delete_contained_entities();
    participant->delete_publisher(publisher);
  }
};

/// Deletes a Subscriber and what it still contains.
struct DeleteSubscriber {
  eprosima::fastdds::dds::DomainParticipant* participant = nullptr;
  void operator()(eprosima::fastdds::dds::Subscriber* subscriber) const {
    subscriber->delete_contained_entities();
    participant->delete_subscriber(subscriber);
  }
};

struct DeleteWriter {
  eprosima::fastdds::dds::Publisher* publisher = nullptr;
  void operator()(eprosima::fastdds::dds::DataWriter* writer) const { publisher->delete_datawriter(writer); }
};

struct DeleteReader {
  eprosima::fastdds::dds::Subscriber* subscriber = nullptr;
  void operator()(eprosima::fastdds::dds::DataReader* reader) const { subscriber->delete_datareader(reader); }
};

}  // namespace detail

using OwnedPublisher = std::unique_ptr<eprosima::fastdds::dds::Publisher, detail::DeletePublisher>;
using OwnedSubscriber = std::unique_ptr<eprosima::fastdds::dds::Subscriber, detail::DeleteSubscriber>;
using OwnedWriter = std::unique_ptr<eprosima::fastdds::dds::DataWriter, detail::DeleteWriter>;
using OwnedReader = std::unique_ptr<eprosima::fastdds::dds::DataReader, detail::DeleteReader>;

/// Takes a publisher `participant` created (Participant::publisher throws rather than returning none).
inline OwnedPublisher own(Participant& participant, eprosima::fastdds::dds::Publisher* publisher) {
  return OwnedPublisher(publisher, detail::DeletePublisher{participant.get()});
}

/// Takes a subscriber `participant` created.
inline OwnedSubscriber own(Participant& participant, eprosima::fastdds::dds::Subscriber* subscriber) {
  return OwnedSubscriber(subscriber, detail::DeleteSubscriber{participant.get()});
}

/// Takes a writer `publisher` created.
/// @throws rsg::EnvironmentError naming `what` when Fast DDS refused it (`writer` is null).
inline OwnedWriter own(eprosima::fastdds::dds::Publisher& publisher,
                       eprosima::fastdds::dds::DataWriter* writer, std::string_view what) {
  if (writer == nullptr) throw EnvironmentError("cannot create " + std::string(what));
  return OwnedWriter(writer, detail::DeleteWriter{&publisher});
}

/// Takes a reader `subscriber` created.
/// @throws rsg::EnvironmentError naming `what` when Fast DDS refused it (`reader` is null).
inline OwnedReader own(eprosima::fastdds::dds::Subscriber& subscriber,
                       eprosima::fastdds::dds::DataReader* reader, std::string_view what) {
  if (reader == nullptr) throw EnvironmentError("cannot create " + std::string(what));
  return OwnedReader(reader, detail::DeleteReader{&subscriber});
}

}  // namespace rsg::dds
