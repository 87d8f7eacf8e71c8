// libFuzzer entry point: the KBL reader, in memory (parse_harness_kbl). A harness it
// accepts must survive its own round trip, as kbl_write.hpp promises: written back as KBL
// and read again it gives the same topology, and written once more the same text.
#include "fuzz_support.hpp"

#include "core/io/kbl_read.hpp"
#include "core/io/kbl_write.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  loom::fuzz::expect_only_input_errors([&] {
    const loom::Harness h = loom::parse_harness_kbl(std::move(text), "fuzz.kbl");
    const std::string written = loom::harness_to_kbl(h);
    loom::Harness again;
    try {
      again = loom::parse_harness_kbl(written, "written.kbl");
    } catch (const loom::InputError& e) {
      loom::fuzz::finding(std::string("a harness read from the input is written as KBL the reader refuses: ") +
                          e.what());
    }
    if (again.cables.size() != h.cables.size() || again.segments.size() != h.segments.size() ||
        again.ports.size() != h.ports.size())
      loom::fuzz::finding("KBL round trip changes the topology: " + std::to_string(h.cables.size()) + " cables, " +
                          std::to_string(h.segments.size()) + " segments, " + std::to_string(h.ports.size()) +
                          " ports read; " + std::to_string(again.cables.size()) + ", " +
                          std::to_string(again.segments.size()) + ", " + std::to_string(again.ports.size()) +
                          " read back");
    if (loom::harness_to_kbl(again) != written) loom::fuzz::finding("KBL written twice differs");
  });
  return 0;
}
