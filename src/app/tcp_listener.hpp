// How rsg's TCP servers (rsg_gateway's /metrics, rsg_view's page) start listening, accept, and
// bound the connections an outsider can make them hold, in one place.
//
// The bounds (docs/security.md, "What an attacker on the network can and cannot do"):
// - ConnectionTable: connections per client address and in total. When one more connection would
//   pass a limit, the oldest connection that is only waiting (for a request, or for the rest of
//   one) makes room, from the address holding the most connections; only when none is waiting is
//   the new one refused. A client that connects and asks at once (a health probe) is therefore
//   served however many slow or idle connections an attacker keeps open: theirs are older.
// - AcceptLoop: an accept that fails (EMFILE at the fd limit, ENFILE, ENOBUFS) waits before the
//   next try. The connection that failed stays in the listen backlog, so trying again at once
//   fails again at once: a busy loop that serves no one.
#pragma once

#include <spdlog/spdlog.h>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/system/error_code.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <list>
#include <map>
#include <optional>
#include <string>
#include <utility>

namespace rsg::app {

/// Opens `acceptor` on `endpoint`'s protocol, binds it with SO_REUSEADDR (a restarted server gets
/// its port back while the old connections linger in TIME_WAIT) and listens. Returns the first
/// failure, for the caller to turn into its own error; the acceptor is then unusable.
inline boost::system::error_code listen_on(boost::asio::ip::tcp::acceptor& acceptor,
                                           const boost::asio::ip::tcp::endpoint& endpoint) {
  namespace net = boost::asio;
  boost::system::error_code ec;
  acceptor.open(endpoint.protocol(), ec);
  if (!ec) acceptor.set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) acceptor.bind(endpoint, ec);
  if (!ec) acceptor.listen(net::socket_base::max_listen_connections, ec);
  return ec;
}

/// Which limit a connection met.
enum class ConnectionLimit { kPerAddress, kTotal };

/// The open connections of one server, by client address and age. I/O thread only.
class ConnectionTable {
 public:
  using Address = boost::asio::ip::address;

  /// A connection the table may close to make room for a newer one.
  class Member {
   public:
    /// Closes the connection. The table has already forgotten it (its Slot is empty).
    virtual void evict() = 0;

   protected:
    ~Member() = default;
  };

  class Slot;

  struct Limits {
    std::size_t total = 32;
    std::size_t per_address = 8;
  };

  /// Whether a connection from an address may open, and which limit it met on the way (then an
  /// older waiting connection was evicted, or, with `admitted` false, none could be).
  struct Admission {
    bool admitted = true;
    std::optional<ConnectionLimit> limit;
  };

  explicit ConnectionTable(Limits limits) : limits_(limits) {}
  ConnectionTable(const ConnectionTable&) = delete;
  ConnectionTable& operator=(const ConnectionTable&) = delete;

  /// Makes room for one more connection from `address`, evicting at most one waiting connection.
  /// Join a Slot right after an admission: the next call counts on it.
  Admission make_room(const Address& address) {
    const auto held = count(address);
    if (held >= limits_.per_address) {
      Entry* victim = nullptr;
      for (auto& entry : entries_)
        if (entry.waiting && entry.address == address) {
          victim = &entry;
          break;
        }
      return evict_or_refuse(victim, ConnectionLimit::kPerAddress);
    }
    if (entries_.size() >= limits_.total) {
      // The oldest waiting connection of the address holding the most.
      Entry* victim = nullptr;
      std::size_t most = 0;
      for (auto& entry : entries_) {
        if (!entry.waiting) continue;
        const auto n = count(entry.address);
        if (n > most) {
          most = n;
          victim = &entry;
        }
      }
      return evict_or_refuse(victim, ConnectionLimit::kTotal);
    }
    return {};
  }

  /// Closes the oldest waiting connection, if any (at the fd limit: room for the next accept).
  bool evict_oldest_waiting() {
    for (auto& entry : entries_)
      if (entry.waiting) return evict_or_refuse(&entry, ConnectionLimit::kTotal).admitted;
    return false;
  }

  std::size_t size() const { return entries_.size(); }
  std::size_t count(const Address& address) const {
    const auto it = per_address_.find(address);
    return it == per_address_.end() ? 0 : it->second;
  }
  const Limits& limits() const { return limits_; }

 private:
  struct Entry {
    Address address;
    Member* member;
    Slot* slot;
    bool waiting;
  };

  Admission evict_or_refuse(Entry* victim, ConnectionLimit limit);
  std::list<Entry>::iterator add(const Address& address, Member& member, Slot& slot) {
    ++per_address_[address];
    return entries_.insert(entries_.end(), Entry{address, &member, &slot, false});
  }
  void remove(std::list<Entry>::iterator entry) {
    if (const auto it = per_address_.find(entry->address); it != per_address_.end() && --it->second == 0)
      per_address_.erase(it);
    entries_.erase(entry);
  }

  Limits limits_;
  std::list<Entry> entries_;  // oldest first
  std::map<Address, std::size_t> per_address_;
};

/// A connection's place in a ConnectionTable, for as long as the connection (its owner) lives or
/// until the table evicts it.
class ConnectionTable::Slot {
 public:
  Slot() = default;
  ~Slot() { leave(); }
  Slot(const Slot&) = delete;
  Slot& operator=(const Slot&) = delete;

  void join(ConnectionTable& table, const Address& address, Member& member) {
    leave();
    table_ = &table;
    entry_ = table.add(address, member, *this);
  }
  void leave() {
    if (table_ != nullptr) table_->remove(entry_);
    table_ = nullptr;
  }
  /// Waiting (for a request or the rest of one): the table may evict it for a newer connection.
  void waiting(bool waiting) {
    if (table_ != nullptr) entry_->waiting = waiting;
  }

 private:
  friend class ConnectionTable;
  ConnectionTable* table_ = nullptr;
  std::list<Entry>::iterator entry_;
};

inline ConnectionTable::Admission ConnectionTable::evict_or_refuse(Entry* victim, ConnectionLimit limit) {
  if (victim == nullptr) return {false, limit};
  Member& member = *victim->member;
  victim->slot->table_ = nullptr;
  remove(victim->slot->entry_);
  member.evict();
  return {true, limit};
}

/// Accepts connections for ever, handing each to `on_connection`, until the acceptor closes.
/// After a failed accept it calls `on_failure` (which may close a connection to free an fd) and
/// waits `backoff` (header comment); failures are logged once per power of two and counted in
/// failures().
class AcceptLoop {
 public:
  using Handler = std::function<void(boost::asio::ip::tcp::socket)>;

  AcceptLoop(boost::asio::ip::tcp::acceptor& acceptor, std::string name, Handler on_connection,
             std::function<void()> on_failure = {},
             std::chrono::milliseconds backoff = std::chrono::milliseconds(100))
      : acceptor_(acceptor),
        name_(std::move(name)),
        on_connection_(std::move(on_connection)),
        on_failure_(std::move(on_failure)),
        backoff_(backoff),
        timer_(acceptor.get_executor()) {}

  void start() {
    acceptor_.async_accept([this](boost::system::error_code ec, boost::asio::ip::tcp::socket socket) {
      if (ec == boost::asio::error::operation_aborted || !acceptor_.is_open()) return;
      if (!ec) {
        on_connection_(std::move(socket));
        return start();
      }
      ++failures_;
      if ((failures_ & (failures_ - 1)) == 0)
        spdlog::warn("{}: accept failed {} time(s) so far ({}): trying again every {} ms", name_, failures_,
                     ec.message(), backoff_.count());
      if (on_failure_) on_failure_();
      timer_.expires_after(backoff_);
      timer_.async_wait([this](boost::system::error_code wait_error) {
        if (!wait_error) start();
      });
    });
  }

  /// Closes the acceptor and the backoff timer. I/O thread.
  void stop() {
    boost::system::error_code ignored;
    acceptor_.close(ignored);
    timer_.cancel();
  }

  std::uint64_t failures() const { return failures_; }

 private:
  boost::asio::ip::tcp::acceptor& acceptor_;
  std::string name_;
  Handler on_connection_;
  std::function<void()> on_failure_;
  std::chrono::milliseconds backoff_;
  boost::asio::steady_timer timer_;
  std::uint64_t failures_ = 0;
};

}  // namespace rsg::app
