#pragma once
// terrain::Error: what every library stage throws on bad input or a failed operation.
// The message reads "stage: what went wrong, what to do", one line, ready for a user.

#include <stdexcept>
#include <string>

namespace terrain {

class Error : public std::runtime_error {
  public:
    Error(const std::string& stage, const std::string& message);
    const std::string& stage() const noexcept { return stage_; }

  private:
    std::string stage_;
};

}  // namespace terrain
