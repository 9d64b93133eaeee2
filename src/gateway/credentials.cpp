#include "gateway/credentials.hpp"

#include "rsg/error.hpp"

namespace rsg::gateway {

std::string expand_credentials_directory(std::string_view value, const char* directory,
                                         std::string_view where) {
  std::string out;
  std::size_t from = 0;
  for (std::size_t at = value.find(kCredentialsVariable); at != std::string_view::npos;
       at = value.find(kCredentialsVariable, from)) {
    if (directory == nullptr || *directory == '\0')
      throw InputError(
          std::string(where) +
          ": names ${CREDENTIALS_DIRECTORY}, but CREDENTIALS_DIRECTORY is not set (the unit needs "
          "LoadCredential=, docs/security.md)");
    out.append(value.substr(from, at - from)).append(directory);
    from = at + kCredentialsVariable.size();
  }
  out.append(value.substr(from));
  return out;
}

}  // namespace rsg::gateway
