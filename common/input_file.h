#pragma once
// Input files: the one place where a stage's input bytes are read, with the same checks for every
// format (docs/conventions.md "Input files").
#include <cstddef>
#include <functional>
#include <string>

namespace voroudf {

/// A stream input (stdin, a FIFO, a character device) is refused beyond this many bytes: its size is
/// not known in advance, so this is what bounds the memory a reader can be made to take. Regular files
/// are read whole, whatever their size.
constexpr size_t kMaxStreamBytes = size_t(2) << 30;  // 2 GiB

/// The bytes of input `path`; `-` is stdin. `check_head`, if given, sees the first bytes (up to 64 KiB,
/// fewer if the input is shorter) before the rest is read and throws InputError for the wrong kind of
/// file, so `-i /dev/zero` fails at once instead of filling memory. Throws InputError (exit 3) naming
/// the file: missing, unreadable, a directory, a stream over kMaxStreamBytes, a read error.
std::string ReadInputBytes(const std::string& path, const std::function<void(const std::string& head)>& check_head = {});

/// How input `path` is named in messages: "stdin" for `-`, else the path.
inline std::string InputName(const std::string& path) { return path == "-" ? "stdin" : path; }

/// Throws InputError naming `path` unless it is a readable regular file (for readers that seek).
void CheckInputFile(const std::string& path);

}  // namespace voroudf
