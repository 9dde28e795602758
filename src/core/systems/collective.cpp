#include "core/systems/collective.hpp"

#include <cstring>

#include "core/base/exact_sum.hpp"

namespace mfree {

namespace {
// A failure message travels as this many doubles (its bytes).
constexpr int kMsgDoubles = 64;

void check(mfree_status_t st, const char *what) {
  if (st != MFREE_SUCCESS)
    throw Error(st, std::string("the host's ") + what + " callback failed with status " + std::to_string(st) + " (" +
                        mfree_status_string(st) + ")");
}
}  // namespace

double Collective::pack(int64_t v) {
  double d;
  std::memcpy(&d, &v, sizeof d);
  return d;
}

int64_t Collective::unpack(double d) {
  int64_t v;
  std::memcpy(&v, &d, sizeof v);
  return v;
}

void Collective::exchange(int32_t ncomp, double *field, int64_t ld) const {
  check(ex_(user_, ncomp, field, ld), "exchange");
}

std::vector<double> Collective::allgather(const double *in, int64_t n) const {
  int64_t total = 0;
  check(ag_(user_, in, n, nullptr, 0, &total), "allgather");
  std::vector<double> out(static_cast<size_t>(total));
  allgather(in, n, out.data(), total);
  return out;
}

void Collective::allgather(const double *in, int64_t n, double *out, int64_t total) const {
  int64_t got = 0;
  check(ag_(user_, in, n, out, total, &got), "allgather");
  if (got != total)
    throw Error(MFREE_ERR_INTERNAL, "the all-gather returned " + std::to_string(got) + " values, expected " +
                                        std::to_string(total) + " (ranks changed their counts?)");
}

int Collective::size() const {
  if (size_ == 0) {
    const double one = 1.0;
    size_ = static_cast<int>(allgather(&one, 1).size());
  }
  return size_;
}

Report Collective::agree_from(const std::vector<double> &statuses, const Report &mine) const {
  int who = -1;
  for (int pass = 0; pass < 2 && who < 0; ++pass)  // errors first, then failures
    for (size_t p = 0; p < statuses.size() && who < 0; ++p)
      if (pass == 0 ? statuses[p] < 0 : statuses[p] > 0) who = static_cast<int>(p);
  if (who < 0) return Report();
  // every failing rank sends its message; the chosen one is read
  double msg[kMsgDoubles] = {0};
  if (!mine.ok()) std::strncpy(reinterpret_cast<char *>(msg), mine.message.c_str(), sizeof msg - 1);
  const std::vector<double> all = allgather(msg, mine.ok() ? 0 : kMsgDoubles);
  int before = 0;
  for (int p = 0; p < who; ++p) before += statuses[p] != 0;
  char text[sizeof msg] = {0};
  if (all.size() >= static_cast<size_t>(before + 1) * kMsgDoubles)
    std::memcpy(text, &all[static_cast<size_t>(before) * kMsgDoubles], sizeof text - 1);
  Report r;
  r.status = static_cast<mfree_status_t>(statuses[who]);
  r.message = "rank " + std::to_string(who) + ": " + text;
  return r;
}

bool Collective::take_pending(Report &fault) const {
  if (pending_.ok()) return false;
  fault = pending_;
  pending_ = Report();
  return true;
}

void Collective::exact_totals(ExactSum *s, int n, double *out) const {
  const int W = ExactSum::kWords;
  const size_t rec = static_cast<size_t>(n) * W;
  std::vector<double> mine(rec);
  for (int k = 0; k < n; ++k) {
    s[k].normalise();  // (words below 2^53: exact as doubles)
    for (int w = 0; w < W; ++w) mine[static_cast<size_t>(k) * W + w] = static_cast<double>(s[k].words()[w]);
  }
  const std::vector<double> all = allgather(mine.data(), static_cast<int64_t>(rec));
  std::vector<int64_t> words(W);
  for (int k = 0; k < n; ++k) {
    ExactSum t;
    for (size_t p = 0; rec > 0 && p < all.size() / rec; ++p) {
      for (int w = 0; w < W; ++w) words[w] = static_cast<int64_t>(all[p * rec + static_cast<size_t>(k) * W + w]);
      t.add_words(words.data());
    }
    out[k] = t.value();
  }
}

Report Collective::agree(const Report &mine) const {
  const double st = static_cast<double>(mine.status);
  std::vector<double> all(static_cast<size_t>(size()));
  allgather(&st, 1, all.data(), static_cast<int64_t>(all.size()));
  return agree_from(all, mine);
}

}  // namespace mfree
