#include "fuzz_support.hpp"

#include "core/error.hpp"

#include <cxxabi.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fstream>
#include <iterator>
#include <memory>
#include <system_error>
#include <typeinfo>
#include <unistd.h>

namespace loom::fuzz {

namespace {

std::filesystem::path make_scratch_dir() {
  std::string tmpl = (std::filesystem::temp_directory_path() / "loom-fuzz-XXXXXX").string();
  if (!mkdtemp(tmpl.data())) finding("cannot create a scratch directory under " + tmpl);
  return tmpl;
}

std::string demangled(const char* name) {
  int status = 0;
  std::unique_ptr<char, void (*)(void*)> d(abi::__cxa_demangle(name, nullptr, nullptr, &status), std::free);
  return status == 0 && d ? d.get() : name;
}

}  // namespace

const std::filesystem::path& scratch_dir() {
  // Never destroyed: the exit handler that removes the directory still needs its name.
  static const std::filesystem::path* dir = [] {
    auto* d = new std::filesystem::path(make_scratch_dir());
    // libFuzzer leaves through exit() at every normal end (time budget, -runs) and after
    // its own crash reports, so the directory goes with the process.
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(*dir, ec);
    });
    return d;
  }();
  return *dir;
}

void write_bytes(const std::filesystem::path& path, const std::uint8_t* data, std::size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) finding("cannot write " + path.string());
}

void write_text(const std::filesystem::path& path, const std::string& text) {
  write_bytes(path, reinterpret_cast<const std::uint8_t*>(text.data()), text.size());
}

void keep_recent(const std::uint8_t* data, std::size_t size) {
  // Read once: the environment does not change while the fuzzer runs.
  static const long ring = [] {
    const char* n = std::getenv("LOOM_FUZZ_KEEP_RECENT");
    return n && std::getenv("LOOM_FUZZ_KEEP_DIR") ? std::strtol(n, nullptr, 10) : 0L;
  }();
  if (ring <= 0) return;
  static long run = 0;
  static const std::filesystem::path dir = std::getenv("LOOM_FUZZ_KEEP_DIR");
  auto name = [](long k) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "recent-%012ld", k);
    return dir / buf;
  };
  std::error_code ec;
  if (run >= ring) std::filesystem::remove(name(run - ring), ec);  // the ring holds the last `ring` runs
  write_bytes(name(run++), data, size);
}

std::string read_test_data(const std::string& name) {
  std::ifstream in(std::filesystem::path(LOOM_TEST_DATA) / name, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in) finding("cannot read tests/data/" + name);
  return text;
}

std::filesystem::path copy_test_data(const std::string& name, const std::string& as) {
  const std::filesystem::path to = scratch_dir() / as;
  std::error_code ec;
  std::filesystem::copy_file(std::filesystem::path(LOOM_TEST_DATA) / name, to,
                             std::filesystem::copy_options::overwrite_existing, ec);
  if (ec) finding("cannot copy tests/data/" + name + ": " + ec.message());
  return to;
}

void expect_only_input_errors(const std::function<void()>& body) {
  try {
    body();
  } catch (const InputError&) {
    // Bad input, reported as the command line would (exit 2): the expected outcome.
  } catch (const std::exception& e) {
    finding("exception " + demangled(typeid(e).name()) + " escaped (not an InputError): " + e.what());
  } catch (...) {
    const std::type_info* t = abi::__cxa_current_exception_type();
    finding("exception of type " + (t ? demangled(t->name()) : std::string("?")) +
            " escaped (not derived from std::exception)");
  }
}

void finding(const std::string& what) {
  std::fprintf(stderr, "==loom-fuzz== FINDING: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

}  // namespace loom::fuzz
