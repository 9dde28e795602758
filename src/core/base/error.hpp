// Internal error and report types. Core code throws mfree::Error for misuse (negative
// statuses); data-dependent failures (positive statuses) are returned as a Report so
// that the call can finish the batch.
#pragma once

#include <stdexcept>
#include <string>

#include "mfree.h"

namespace mfree {

class Error : public std::runtime_error {
 public:
  Error(mfree_status_t status, const std::string &msg)
      : std::runtime_error(msg), status_(status) {}
  mfree_status_t status() const noexcept { return status_; }

 private:
  mfree_status_t status_;
};

// Outcome of a call that may partly fail on data: status 0 or positive, plus message.
struct Report {
  mfree_status_t status = MFREE_SUCCESS;
  std::string message;

  // Keep the first failure's message but let a later, different code be recorded only
  // if nothing failed before: the first failure is usually the informative one.
  void fail(mfree_status_t s, const std::string &msg) {
    if (status == MFREE_SUCCESS) {
      status = s;
      message = msg;
    }
  }
  bool ok() const { return status == MFREE_SUCCESS; }
};

}  // namespace mfree
