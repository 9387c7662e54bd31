// proxima_soak: seeded random queries of every kind against the invariants
// of the accuracy standard. Usage (docs/accuracy.md, "The soak"):
//
//   proxima_soak [--seed S] [--queries N | --seconds T] [--kinds k1,k2,...]
//                [--episode E] [--reports R]
//
// Kinds: convex tracked rounded compound mesh toi (default all, drawn with
// the tour's weights 4 3 2 1 2 3). Each violation is one JSON line on
// standard output (with the seed, the episode and, where the JSON form can
// say it, a `proxima query` line); the last line is the summary: queries,
// checks and violations per invariant. Exit status 1 when any check failed.
// SPDX-License-Identifier: BSD-3-Clause
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>

#include "soak.h"

namespace {

using proxima::soak::Kind;

struct Arguments {
  std::uint64_t seed = 1;
  std::uint64_t queries = 0;
  double seconds = 0;
  std::optional<std::uint64_t> episode;
  int reports = 5;
  std::vector<Kind> kinds;
};

[[noreturn]] void usage(const std::string& why) {
  std::fprintf(stderr,
               "proxima_soak: %s\nusage: proxima_soak [--seed S] [--queries N | --seconds T] "
               "[--kinds convex,tracked,rounded,compound,mesh,toi] [--episode E] [--reports R]\n",
               why.c_str());
  std::exit(2);
}

std::uint64_t parse_count(const char* text, const char* option) {
  char* end = nullptr;
  const double value = std::strtod(text, &end);  // 1e7 as well as 10000000
  if (end == text || *end != '\0' || !(value >= 0) || value > 1e18)
    usage(std::string(option) + " takes a non-negative number, not '" + text + "'");
  return static_cast<std::uint64_t>(value);
}

Arguments parse(int argc, char** argv) {
  Arguments a;
  for (int i = 1; i < argc; ++i) {
    const std::string option = argv[i];
    if (i + 1 >= argc) usage(option + " needs a value");
    const char* value = argv[++i];
    if (option == "--seed") {
      a.seed = parse_count(value, "--seed");
    } else if (option == "--queries") {
      a.queries = parse_count(value, "--queries");
    } else if (option == "--seconds") {
      a.seconds = static_cast<double>(parse_count(value, "--seconds"));
    } else if (option == "--episode") {
      a.episode = parse_count(value, "--episode");
    } else if (option == "--reports") {
      a.reports = static_cast<int>(parse_count(value, "--reports"));
    } else if (option == "--kinds") {
      std::string list = value;
      std::size_t start = 0;
      while (start <= list.size()) {
        const std::size_t comma = std::min(list.find(',', start), list.size());
        const std::string name = list.substr(start, comma - start);
        bool known = false;
        for (Kind k : proxima::soak::kAllKinds) {
          if (name == proxima::soak::to_string(k)) {
            a.kinds.push_back(k);
            known = true;
          }
        }
        if (!known) usage("unknown kind '" + name + "' in --kinds");
        start = comma + 1;
      }
    } else {
      usage("unknown option " + option);
    }
  }
  if (a.queries == 0 && a.seconds == 0 && !a.episode) a.queries = 100000;
  return a;
}

// The tour's weights: convex 4, tracked 3, rounded 2, compound 1, mesh 2, toi 3.
int weight(Kind kind) {
  switch (kind) {
    case Kind::convex:
      return 4;
    case Kind::tracked:
    case Kind::toi:
      return 3;
    case Kind::rounded:
    case Kind::mesh:
      return 2;
    case Kind::compound:
      return 1;
  }
  return 1;
}

// The episode's own stream: splitmix64 of (seed, episode), so that an
// episode replays alone.
std::uint64_t episode_seed(std::uint64_t seed, std::uint64_t episode) {
  std::uint64_t z = seed * 0x9e3779b97f4a7c15ULL + episode + 0x632be59bd9b4e019ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

}  // namespace

int main(int argc, char** argv) {
  const Arguments args = parse(argc, argv);
  std::vector<Kind> deck;
  for (Kind k : args.kinds.empty() ? std::vector<Kind>(std::begin(proxima::soak::kAllKinds),
                                                       std::end(proxima::soak::kAllKinds))
                                   : args.kinds)
    for (int w = 0; w < weight(k); ++w) deck.push_back(k);

  proxima::soak::Ledger ledger(args.seed, args.reports);
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  const auto run = [&](std::uint64_t episode) {
    proxima::soak::Context context{ledger, proxima::soak::Draw(episode_seed(args.seed, episode)),
                                   args.seed, episode};
    const Kind kind = deck[static_cast<std::size_t>(context.draw.integer(0, static_cast<int>(deck.size())))];
    ledger.set_episode(episode, kind);
    try {
      proxima::soak::run_episode(kind, context);
    } catch (const std::exception& e) {
      ledger.violation("exception", "\"error\":\"" + std::string(e.what()) + "\"");
    }
  };
  if (args.episode) {
    run(*args.episode);
  } else {
    for (std::uint64_t episode = 0;; ++episode) {
      if (args.queries > 0 && ledger.query_count() >= args.queries) break;
      if (args.seconds > 0 && elapsed() >= args.seconds) break;
      run(episode);
    }
  }
  std::printf("%s\n", ledger.summary(elapsed()).c_str());
  return ledger.violation_count() == 0 ? 0 : 1;
}
