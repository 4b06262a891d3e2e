// the writers' file helpers (io/file.cpp): zero-padded frame names, whole files written and read back
// byte for byte, and every failure (a folder that is not there, a full disk, a missing file) thrown as a
// soak::Error naming the file and the reason
#include "io/file.hpp"

#include <gtest/gtest.h>

#include <soak/error.hpp>
#include <soak/output.hpp>

#include "io/io_support.hpp"
#include "io/obj.hpp"
#include "io/output.hpp"
#include "io/ply.hpp"

#include <filesystem>
#include <string>

namespace soak {
namespace {

using namespace soak::testing;

// every writer names the path it could not open
TEST(IoErrors, UnwritablePathThrowsNamingIt) {
  const Fixture f = makeFixture();
  const std::string missing = (fs::temp_directory_path() / "soak_no_such_dir_io" / "sub").string();
  fs::remove_all(fs::temp_directory_path() / "soak_no_such_dir_io");
  const auto expectNamed = [&](const std::string& path, auto&& write) {
    try {
      write(path);
      ADD_FAILURE() << "no error writing " << path;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  };
  expectNamed(missing + "/cloth_0000.obj", [&](const std::string& p) { writeClothObj(p, f.model, f.state); });
  expectNamed(missing + "/cloth_0000.ply", [&](const std::string& p) { writeClothPly(p, f.model, f.state); });
  expectNamed(missing + "/water_0000.ply", [&](const std::string& p) { writeWaterPly(p, f.state); });
  expectNamed(missing + "/stats.jsonl", [&](const std::string& p) { JsonLinesWriter w(p); });
  expectNamed(missing + "/water_0000.ply", [&](const std::string& p) { readPly(p); });
  expectNamed(missing, [&](const std::string& p) { writeFrameFiles(p, f.model, f.state, OutputSettings{}, 0); });
}

TEST(IoFile, FrameNumbersArePaddedToFourDigits) {
  EXPECT_EQ(frameFileName("cloth", 0, "obj"), "cloth_0000.obj");
  EXPECT_EQ(frameFileName("water", 42, "ply"), "water_0042.ply");
  EXPECT_EQ(frameFileName("frame", 9999, "png"), "frame_9999.png");
  EXPECT_EQ(frameFileName("frame", 12345, "png"), "frame_12345.png");  // wider, never cut
}

// binary content (NUL, CR LF, every byte value) comes back unchanged, and a second write truncates
TEST(IoFile, TextRoundTripsByteForByteAndAWriteTruncates) {
  const fs::path dir = tempDir("roundtrip");
  const std::string path = (dir / "bytes.bin").string();
  std::string bytes;
  for (int k = 0; k < 3 * 256; ++k) bytes.push_back(static_cast<char>(k % 256));
  bytes += "\r\nend";
  writeTextFile(path, bytes);
  EXPECT_EQ(fs::file_size(path), bytes.size());
  EXPECT_EQ(readTextFile(path), bytes);
  writeTextFile(path, "short");
  EXPECT_EQ(readTextFile(path), "short");
  fs::remove_all(dir);
}

TEST(IoFile, ReadingAMissingFileOrWritingOverAFolderNamesIt) {
  const fs::path dir = tempDir("missing");
  const std::string absent = (dir / "absent.txt").string();
  try {
    readTextFile(absent);
    FAIL() << "read a file that is not there";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), absent + ": cannot open for reading: No such file or directory");
  }
  try {
    writeTextFile(dir.string(), "x");
    FAIL() << "wrote over a folder";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), dir.string() + ": cannot open for writing: Is a directory");
  }
  fs::remove_all(dir);
}

// /dev/full accepts the open and fails every write (ENOSPC): the failed write becomes an error naming the
// file, so a full disk is never a silently short frame
TEST(IoFile, AFullDiskIsAWriteFailureNamingTheFile) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full on this system";
  for (size_t size : {size_t(10), size_t(1) << 16}) {  // failing in finishWrite's flush, or in the write itself
    try {
      writeTextFile("/dev/full", std::string(size, 'x'));
      FAIL() << "a write to /dev/full succeeded, " << size << " bytes";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).rfind("/dev/full: write failed: ", 0), 0u) << e.what();
    }
  }
  std::ofstream out = openForWrite("/dev/full");
  out << "x";
  EXPECT_THROW(finishWrite(out, "/dev/full"), Error);
  EXPECT_TRUE(fs::is_character_file("/dev/full")) << "a device was replaced by a renamed file";
}

// a file being written lives under NAME.part: the old file stays whole until commit() replaces it,
// and a write abandoned (an exception, a full disk) leaves the old file and no .part behind
TEST(IoFile, AnAtomicFileReplacesTheOldOneOnlyWhenComplete) {
  const fs::path dir = tempDir("atomic");
  const std::string path = (dir / "frame.txt").string();
  writeTextFile(path, "old");
  {
    AtomicFile f(path);
    f.out() << "new, half written";
    f.out().flush();
    EXPECT_EQ(readTextFile(path), "old");
    EXPECT_TRUE(fs::exists(path + ".part"));
  }
  EXPECT_EQ(readTextFile(path), "old");
  EXPECT_FALSE(fs::exists(path + ".part"));
  AtomicFile f(path);
  f.out() << "new";
  f.commit();
  EXPECT_EQ(readTextFile(path), "new");
  EXPECT_FALSE(fs::exists(path + ".part"));
  fs::remove_all(dir);
}

// a full disk is named as such, also when the failing write was a block written at once (larger than
// the stream's buffer) before finishWrite
TEST(IoFile, AFullDiskIsNamedAsSuchWhateverTheWriteSize) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full on this system";
  try {
    writeTextFile("/dev/full", std::string(size_t(1) << 16, 'x'));
    FAIL() << "a write to /dev/full succeeded";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "/dev/full: write failed: No space left on device");
  }
}

}  // namespace
}  // namespace soak
