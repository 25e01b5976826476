#include "anvil/io/keyword.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <limits>
#include <map>
#include <memory>
#include <new>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "anvil/io/files.hpp"

namespace anvil {

namespace fs = std::filesystem;

namespace {

// Nested *INCLUDEs deeper than this are surely a mistake (cycles are caught by name).
constexpr int max_include_depth = 40;

// Text from the deck for a message: short, and printable whatever the file holds.
std::string shown(std::string_view s) {
  std::string out;
  for (char c : s.substr(0, 60)) {
    const auto u = static_cast<unsigned char>(c);
    out += (u >= 0x20 && u < 0x7f) ? std::string(1, c) : fmt::format("\\x{:02x}", u);
  }
  if (s.size() > 60) out += "...";
  return out;
}

std::string_view trim(std::string_view s) {
  auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; };
  while (!s.empty() && blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && blank(s.back())) s.remove_suffix(1);
  return s;
}

std::string upper(std::string_view s) {
  std::string out(s);
  for (auto& c : out)
    if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 'a' + 'A');
  return out;
}

bool starts_with(std::string_view s, std::string_view prefix) {
  return s.substr(0, prefix.size()) == prefix;
}
bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

// ---- the deck as keyword blocks ---------------------------------------------------------

// One data line of a keyword, and where it came from. The text lives in the Lexer's file
// store, which outlives every Line.
struct Line {
  std::string_view text;
  const std::string* file;
  int line;
  SourceLocation where(std::string key = "") const { return {*file, line, std::move(key)}; }
};

// One keyword (`*MAT_ELASTIC_TITLE`) with its data lines, comments removed, *INCLUDEs
// already expanded around it.
struct Block {
  std::string name; // upper case, without the '*' and the format suffix
  Line head;        // the keyword line itself
  bool long_format = false;
  bool i10 = false;
  std::vector<Line> lines;
  // How far a reader's Cursor got: the lines it took, or all of them when it skips the
  // rest on purpose (a keyword anvil only lists). The reader checks it after each keyword
  // so that no card is dropped silently (KeywordReader::read).
  mutable std::optional<std::size_t> taken;
  std::string key(std::string_view field) const { return fmt::format("*{}.{}", name, field); }
};

// Splits files into keyword blocks, following *INCLUDE and stopping at *END.
class Lexer {
public:
  explicit Lexer(bool require_keyword) : require_keyword_(require_keyword) {}

  // Lexes `text` (the main file); `name` names it in messages.
  void lex_main(std::string_view text, const std::string& name, const fs::path& dir) {
    files_.push_back(name);
    std::vector<std::string> stack{name};
    lex(text, &files_.back(), dir, stack, true);
  }

  std::vector<Block>& blocks() { return blocks_; }

private:
  void lex(std::string_view text, const std::string* file, const fs::path& dir,
           std::vector<std::string>& stack, bool main_file) {
    std::size_t pos = 0;
    // A UTF-8 byte-order mark, as some Windows editors write it, is no part of the deck.
    if (starts_with(text, "\xEF\xBB\xBF")) pos = 3;
    int line_no = 0;
    std::optional<std::size_t> current; // index of the block taking data lines
    bool in_include = false;
    std::string pending_include; // a file name continued with " +"
    int pending_line = 0;
    bool seen_keyword = false;
    // A format chosen on an included file's *KEYWORD card holds for that file only.
    const bool outer_long = long_, outer_i10 = i10_;
    struct Restore {
      Lexer& l;
      bool main, lng, i10;
      ~Restore() {
        if (!main) l.long_ = lng, l.i10_ = i10;
      }
    } restore{*this, main_file, outer_long, outer_i10};
    while (pos < text.size()) {
      const auto end = text.find('\n', pos);
      const auto stop = end == std::string_view::npos ? text.size() : end;
      std::string_view raw = text.substr(pos, stop - pos);
      pos = stop + 1;
      ++line_no;
      if (!raw.empty() && raw.back() == '\r') raw.remove_suffix(1);
      const std::string_view t = trim(raw);
      if (!t.empty() && t.front() == '$') continue; // comment
      const Line ln{raw, file, line_no};
      if (!raw.empty() && raw.front() == '*') {
        if (in_include && !pending_include.empty())
          throw InputError({*file, pending_line, "*INCLUDE"},
                           "the file name ends with ' +' but no continuation line follows");
        in_include = false;
        current.reset();
        // `*NAME [options]`: the name runs to the first blank; '+', '-', '%' select the
        // long, standard or I10 format for this keyword.
        std::string_view rest = raw.substr(1);
        const auto blank = rest.find_first_of(" \t");
        std::string name = upper(trim(rest.substr(0, blank)));
        const std::string options =
            upper(blank == std::string_view::npos ? "" : trim(rest.substr(blank)));
        bool long_format = long_, i10 = i10_;
        auto suffix = [&](char c) {
          if (c == '+') long_format = true;
          if (c == '-') long_format = i10 = false;
          if (c == '%') i10 = true;
        };
        while (!name.empty() && (name.back() == '+' || name.back() == '-' || name.back() == '%')) {
          suffix(name.back());
          name.pop_back();
        }
        if (options == "+" || options == "-" || options == "%") suffix(options[0]);
        if (name.empty()) throw InputError(ln.where(), "a '*' line without a keyword name");
        if (main_file && require_keyword_ && !seen_keyword && name != "KEYWORD")
          throw InputError(
              ln.where(),
              fmt::format("an LS-DYNA keyword deck starts with *KEYWORD, found *{}", shown(name)));
        seen_keyword = true;
        if (name == "END") return; // the rest of this file is not read
        if (name == "KEYWORD") {
          keyword_options(options, ln);
          continue;
        }
        if (name == "INCLUDE") {
          in_include = true;
          continue;
        }
        blocks_.push_back(Block{name, ln, long_format, i10, {}, std::nullopt});
        current = blocks_.size() - 1;
        continue;
      }
      if (in_include) {
        if (t.empty()) continue;
        // A long file name continues on the next line after " +".
        if (t.size() >= 2 && ends_with(t, " +")) {
          if (pending_include.empty()) pending_line = line_no;
          pending_include += std::string(trim(t.substr(0, t.size() - 2)));
          continue;
        }
        std::string name = pending_include + std::string(t);
        const int at = pending_include.empty() ? line_no : pending_line;
        pending_include.clear();
        include(name, Line{raw, file, at}, dir, stack);
        continue;
      }
      if (!current) {
        if (t.empty()) continue;
        if (!seen_keyword && main_file && require_keyword_)
          throw InputError(ln.where(), "an LS-DYNA keyword deck starts with *KEYWORD, found "
                                       "data ('" +
                                           shown(t) + "')");
        throw InputError(ln.where(), fmt::format("data without a keyword: '{}'", shown(t)));
      }
      blocks_[*current].lines.push_back(ln);
    }
    if (in_include && !pending_include.empty())
      throw InputError({*file, pending_line, "*INCLUDE"},
                       "the file name ends with ' +' but no continuation line follows");
    if (main_file && require_keyword_ && !seen_keyword)
      throw InputError({*file, std::max(line_no, 1), ""},
                       "no keywords: an LS-DYNA keyword deck starts with *KEYWORD");
  }

  // `*KEYWORD` options: LONG=Y (long format everywhere), LONG=S (standard), I10=Y; a
  // memory size is LS-DYNA's business.
  void keyword_options(const std::string& options, const Line& ln) {
    std::istringstream in(options);
    std::string tok;
    while (in >> tok) {
      if (tok == "LONG=Y")
        long_ = true;
      else if (tok == "LONG=S" || tok == "LONG=N")
        long_ = false;
      else if (tok == "I10=Y")
        i10_ = true;
      else if (tok == "I10=N")
        i10_ = false;
      else if (starts_with(tok, "LONG=") || starts_with(tok, "I10="))
        throw InputError(ln.where("*KEYWORD"),
                         fmt::format("unknown format option '{}' (expected LONG=Y, LONG=S or "
                                     "I10=Y)",
                                     shown(tok)));
    }
  }

  void include(const std::string& name, const Line& ln, const fs::path& dir,
               std::vector<std::string>& stack) {
    fs::path p(name);
    if (p.is_relative()) p = (dir / p).lexically_normal(); // ("a.k", not "./a.k")
    std::error_code ec;
    const std::string label = p.string();
    if (!fs::is_regular_file(p, ec))
      throw InputError(ln.where("*INCLUDE"),
                       fmt::format("cannot open the included file '{}'{}", shown(label),
                                   fs::exists(p, ec) ? " (not a file)" : ""));
    const fs::path canon = fs::weakly_canonical(p, ec);
    const std::string id = ec ? label : canon.string();
    if (std::find(stack.begin(), stack.end(), id) != stack.end()) {
      std::string chain;
      for (const auto& s : stack) chain += s + " -> ";
      throw InputError(ln.where("*INCLUDE"), fmt::format("include cycle: {}{}", chain, shown(id)));
    }
    if (static_cast<int>(stack.size()) > max_include_depth)
      throw InputError(ln.where("*INCLUDE"),
                       fmt::format("*INCLUDE nested more than {} deep", max_include_depth));
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    if (!in && !in.eof())
      throw InputError(ln.where("*INCLUDE"),
                       fmt::format("cannot read the included file '{}'", shown(label)));
    texts_.push_back(ss.str());
    files_.push_back(label);
    stack.push_back(id);
    lex(texts_.back(), &files_.back(), p.parent_path(), stack, false);
    stack.pop_back();
  }

  bool require_keyword_;
  bool long_ = false, i10_ = false;
  std::deque<std::string> files_; // names, stable addresses for Line::file
  std::deque<std::string> texts_; // included files' contents, stable for Line::text
  std::vector<Block> blocks_;
};

// ---- cards and fields -------------------------------------------------------------------

// The fields of one card: fixed columns (widths adjusted for the long and I10 formats) or
// comma-separated free format when the line holds a comma. A free-format card holds at
// most the fields its fixed-column form fits in 80 columns (`widths`, continued with the
// last width): more is an error, not fields silently dropped. A list card (a set's ids)
// or a card of a keyword anvil only skips (Extra::keep) keeps them all.
class Card {
public:
  enum class Extra { error, keep };

  Card(const Block& kw, const Line& line, std::initializer_list<int> widths,
       Extra extra = Extra::error)
      : kw_(kw), line_(line) {
    const std::string_view text = line.text;
    fields_.reserve(widths.size());
    if (text.find(',') != std::string_view::npos) {
      std::size_t start = 0;
      for (;;) {
        const auto comma = text.find(',', start);
        fields_.push_back(trim(text.substr(
            start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
        if (comma == std::string_view::npos) break;
        start = comma + 1;
      }
      std::size_t used = fields_.size(); // trailing empty fields are no fields
      while (used > 0 && fields_[used - 1].empty()) --used;
      const int most = fields_in_80_columns(widths);
      if (extra == Extra::error && used > static_cast<std::size_t>(most))
        throw InputError(line.where(kw.key("card")),
                         fmt::format("the card has {} comma-separated fields; a card of *{} "
                                     "here holds at most {}",
                                     used, kw.name, most));
      return;
    }
    if (text.find('\t') != std::string_view::npos)
      throw InputError(line.where(kw.key("card")),
                       "a tab character in a fixed-format card: fields are counted in columns "
                       "(use blanks, or commas for free format)");
    std::size_t col = 0;
    for (int w : widths) {
      const std::size_t width = kw.long_format ? 20 : (kw.i10 && w < 10 ? 10 : w);
      fields_.push_back(col < text.size() ? trim(text.substr(col, width)) : std::string_view());
      col += width;
      ends_.push_back(col);
    }
  }

  // Fixed format: whether field i fills its last column and field i + 1 goes on from it
  // without a blank, as a value too wide for field i does (so do two values that fill
  // their fields exactly: callers ask only once the next field has failed to read).
  bool runs_into_next(int i) const {
    if (i < 0 || i + 1 >= static_cast<int>(ends_.size())) return false;
    const std::string_view text = line_.text;
    const std::size_t end = ends_[static_cast<std::size_t>(i)];
    return end < text.size() && text[end - 1] != ' ' && text[end] != ' ';
  }
  // Fixed format: field i's width in columns.
  std::size_t width(int i) const {
    const auto k = static_cast<std::size_t>(i);
    return ends_[k] - (k == 0 ? 0 : ends_[k - 1]);
  }
  // Fixed format: the text from field i's first non-blank column to the next blank (the
  // value as written, when it runs past its field).
  std::string_view written(int i) const {
    const std::string_view text = line_.text;
    std::size_t start = ends_[static_cast<std::size_t>(i)] - width(i);
    while (start < text.size() && text[start] == ' ') ++start;
    if (start >= text.size()) return {};
    const auto stop = text.find(' ', start);
    return text.substr(start, stop == std::string_view::npos ? stop : stop - start);
  }

  // Fields on the card: its widths in fixed format, every comma-separated one in free.
  int size() const { return static_cast<int>(fields_.size()); }
  // A card of exactly n fields (its fixed form shorter than 80 columns): a field after the
  // n-th, or text after its columns, is an error, not dropped.
  void no_fields_after(int n) const {
    for (int i = n; i < size(); ++i)
      if (!fields_[static_cast<std::size_t>(i)].empty())
        fail("card", fmt::format("*{} has {} fields; this card holds a field more ('{}')", kw_.name,
                                 n, shown(fields_[static_cast<std::size_t>(i)])));
    if (ends_.size() >= static_cast<std::size_t>(n) && n > 0) {
      const std::string_view text = line_.text;
      const std::size_t end = ends_[static_cast<std::size_t>(n - 1)];
      if (end < text.size() && !trim(text.substr(end)).empty())
        fail("card", fmt::format("*{} has {} fields, in {} columns; found '{}' after them",
                                 kw_.name, n, end, shown(trim(text.substr(end)))));
    }
  }
  bool blank(int i) const { return i >= size() || fields_[i].empty(); }

  std::int64_t integer(int i, std::string_view name, std::int64_t def = 0) const {
    if (blank(i)) return def;
    const std::string_view f = unparameter(i, name);
    std::string_view s = f;
    if (!s.empty() && s.front() == '+') s.remove_prefix(1);
    std::int64_t v = 0;
    const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || p != s.data() + s.size()) {
      // "12." and "1.0e3" are integers written as reals; accept them when exact.
      double d = 0;
      if (parse_real(f, d) && d == std::floor(d) && std::abs(d) < 9e15)
        return static_cast<std::int64_t>(d);
      fail(name, fmt::format("{} must be an integer, found '{}'", name, shown(f)));
    }
    return v;
  }

  double real(int i, std::string_view name, double def = 0) const {
    if (blank(i)) return def;
    const std::string_view f = unparameter(i, name);
    double v = 0;
    if (!parse_real(f, v))
      fail(name, fmt::format("{} must be a finite number, found '{}'", name, shown(f)));
    return v;
  }

  // An id: a positive integer (blank or 0 gives `def`, which callers use for "none").
  std::int64_t id(int i, std::string_view name) const {
    const std::int64_t v = integer(i, name, 0);
    if (v < 0) fail(name, fmt::format("{} must not be negative, found {}", name, v));
    return v;
  }

  [[noreturn]] void fail(std::string_view field, const std::string& message) const {
    throw InputError(line_.where(kw_.key(field)), message);
  }
  const Line& line() const { return line_; }
  const std::string& keyword() const { return kw_.name; }

private:
  // The fields of the card's fixed-column form in standard format (80 columns).
  static int fields_in_80_columns(std::initializer_list<int> widths) {
    int columns = 0;
    for (int w : widths) columns += w;
    const int last = widths.size() ? *(widths.end() - 1) : 10;
    return static_cast<int>(widths.size()) + std::max(0, 80 - columns) / last;
  }

  std::string_view unparameter(int i, std::string_view name) const {
    const std::string_view f = fields_[i];
    if (f.front() == '&' || f.front() == '<')
      fail(name, fmt::format("{} is a parameter reference ('{}'); anvil does not read "
                             "*PARAMETER: write the value",
                             name, shown(f)));
    return f;
  }

  // Fortran-style reals: 1.5, 1.5e3, 1.5E+3, 1.5d3, and 1.5-3 (exponent without a letter).
  static bool parse_real(std::string_view f, double& v) {
    std::string s(f);
    for (auto& c : s)
      if (c == 'd' || c == 'D') c = 'e';
    std::size_t start = !s.empty() && s[0] == '+' ? 1 : 0;
    const char* b = s.data() + start;
    const char* e = s.data() + s.size();
    if (b == e) return false;
    // from_chars also reads "inf", "nan" and "infinity": none of them is a number here.
    if (!std::isdigit(static_cast<unsigned char>(*b)) && *b != '.' && *b != '-') return false;
    auto [p, ec] = std::from_chars(b, e, v);
    if (ec != std::errc()) return false;
    if (p != e) {
      // A mantissa followed by a signed exponent without its letter.
      const std::string_view rest(p, static_cast<std::size_t>(e - p));
      if (rest.size() < 2 || (rest[0] != '+' && rest[0] != '-') ||
          s.find('e', start) != std::string::npos)
        return false;
      int ex = 0;
      const char* q = rest.data() + (rest[0] == '+' ? 1 : 0);
      const auto [p2, ec2] = std::from_chars(q, rest.data() + rest.size(), ex);
      if (ec2 != std::errc() || p2 != rest.data() + rest.size()) return false;
      std::string joined(b, p);
      joined += 'e';
      joined += std::string(rest);
      const auto [p3, ec3] = std::from_chars(joined.data(), joined.data() + joined.size(), v);
      if (ec3 != std::errc() || p3 != joined.data() + joined.size()) return false;
    }
    return std::isfinite(v);
  }

  const Block& kw_;
  Line line_;
  std::vector<std::string_view> fields_;
  std::vector<std::size_t> ends_; // fixed format: the column after each field
};

// The message for an id too wide for its fixed-format field `i` (named `field`), which has
// run into the next field (named `next`), with the wider formats that fit it.
std::string wide_id(const Card& card, int i, std::string_view field, std::string_view next) {
  const std::size_t w = card.width(i);
  const std::string wider =
      w < 10   ? fmt::format("*KEYWORD I10=Y or '*{0} %' for 10 characters, *KEYWORD LONG=Y or "
                               "'*{0} +' for 20",
                             card.keyword())
      : w < 20 ? fmt::format("*KEYWORD LONG=Y or '*{} +' for 20 characters", card.keyword())
               : std::string();
  return fmt::format("{} '{}' is wider than its field and runs into {}: *{}'s {} field is {} "
                     "characters wide here (give {}{}comma-separated fields)",
                     field, shown(card.written(i)), next, card.keyword(), field, w, wider,
                     wider.empty() ? "" : ", or ");
}

// The message for a segment's node N1-N4 that is blank, zero or negative.
std::string segment_node_needed(const std::string& name) {
  return fmt::format("{} must be a positive node id{}", name,
                     name == "N4" ? " (a triangle repeats N3 as N4)" : "");
}

// A card of free text (title, heading): the whole line, trimmed.
std::string text_card(const Line& l) {
  return std::string(trim(l.text));
}

// Reads the lines of a block in order; cards past the end are blank (their defaults).
// Every line it hands out is marked taken in the block (Block::taken).
class Cursor {
public:
  explicit Cursor(const Block& b) : b_(b) {
    // Blank lines at the end of a block are layout, not cards with defaults.
    end_ = b.lines.size();
    while (end_ > 0 && trim(b.lines[end_ - 1].text).empty()) --end_;
    b_.taken = 0;
  }
  bool done() const { return i_ >= end_; }
  // The next line, or a blank one at the keyword's line when the block has run out.
  Line next() {
    if (i_ < end_) return take(b_.lines[i_++]);
    return Line{std::string_view(), b_.head.file, b_.head.line};
  }
  // The next non-blank line (list keywords skip blank lines).
  std::optional<Line> next_record() {
    while (i_ < end_) {
      const Line& l = take(b_.lines[i_++]);
      if (!trim(l.text).empty()) return l;
    }
    return std::nullopt;
  }
  // The next line without taking it (none at the block's end).
  std::optional<Line> peek() const {
    if (i_ < end_) return b_.lines[i_];
    return std::nullopt;
  }
  // The rest of the block is not read, on purpose (a keyword anvil only lists).
  void skip_rest() {
    i_ = end_;
    b_.taken = end_;
  }

private:
  const Line& take(const Line& l) {
    b_.taken = i_;
    return l;
  }
  const Block& b_;
  std::size_t i_ = 0, end_ = 0;
};

// After a keyword's reader: a non-blank line it did not take is a card more than the
// keyword holds (a second rigid wall in one *RIGIDWALL_PLANAR, a second
// *CONTROL_TERMINATION card). LS-DYNA's single-definition keywords take one set of
// cards; rather than drop the rest, anvil stops at the first of them.
void check_all_taken(const Block& b) {
  if (!b.taken) return; // not read card by card (ignored keywords are listed instead)
  for (std::size_t i = *b.taken; i < b.lines.size(); ++i) {
    if (trim(b.lines[i].text).empty()) continue;
    const std::size_t n = *b.taken;
    throw InputError(b.lines[i].where("*" + b.name),
                     fmt::format("one data card more than *{} takes: it takes {} card{} here "
                                 "(from line {}), and anvil does not drop the rest (a second "
                                 "definition needs a *{} keyword of its own)",
                                 b.name, n, n == 1 ? "" : "s", b.lines[0].line, b.name));
  }
}

// ---- what the deck defines ----------------------------------------------------------------

struct Where {
  const std::string* file = nullptr;
  int line = 0;
  SourceLocation loc(std::string key = "") const {
    return {file ? *file : std::string(), line, std::move(key)};
  }
  std::string str() const { return fmt::format("{}:{}", file ? *file : "", line); }
};
Where where_of(const Line& l) {
  return {l.file, l.line};
}

struct RawElement {
  std::int64_t eid, pid;
  std::array<std::int64_t, 8> nodes; // node ids
  Where at;
};

// An *ELEMENT_SPH card: particles at nodes NID (to NEND, when given) of part PID, each of
// mass MASS (of volume |MASS| when MASS < 0 or with the _VOLUME option).
struct RawSph {
  std::int64_t nid, nend, pid;
  double mass, volume; // one of them is 0
  Where at;
};

// Where a node's particle went: its particle set, its index there, its card.
struct ParticleAt {
  std::size_t set;
  std::int64_t index;
  const RawSph* card;
};

// A *SECTION_SPH: the smoothing length of its parts' particles.
struct SphSectionCard {
  double cslh, hmin, hmax, sphini;
  Where at;
};
// (The field SPHINI of a section is at its card's line: at.loc("*SECTION_SPH.SPHINI").)

struct PartCard {
  std::int64_t pid, secid, mid, eosid, hgid;
  std::string heading;
  Where at;
};

struct SectionCard {
  std::int64_t elform;
  std::string keyword;
  Where at;
};

// A material as the deck gives it: anvil's model and parameters, or the LS-DYNA keyword
// of a material anvil does not have (an error only if a solid part uses it).
struct MaterialCard {
  std::string keyword;
  std::string model; // empty: unsupported
  ParamValues params;
  std::vector<std::string> notes; // warnings, given only if a part uses the material
  Where at;
  TableValues tables;
  bool rigid = false; // *MAT_RIGID: its parts are rigid bodies
  // *MAT_RIGID CMO = 1: CON1, CON2 (0-7: none, x, y, z, xy, yz, zx, all), the translations
  // and rotations of its bodies held fixed.
  int con1 = 0, con2 = 0;
  // FS, FAIL, PSFAIL: the plastic strain at which its parts' elements erode (0: never).
  double failure_strain = 0;
  // *MAT_PIECEWISE_LINEAR_PLASTICITY's LCSS: the hardening curve, read from its
  // *DEFINE_CURVE when a part uses the material (0: none).
  std::int64_t lcss = 0;
  // The card field each of anvil's parameters came from (for the model's own checks).
  std::map<std::string, SourceLocation, std::less<>> field_of;
};

MaterialCard material_card(const Block& b, std::string model, const Line& l) {
  MaterialCard m;
  m.keyword = b.name;
  m.model = std::move(model);
  m.at = where_of(l);
  return m;
}

struct EosCard {
  std::string keyword;
  // *EOS_GRUNEISEN: bulk sound speed C, the Hugoniot's slopes S1-S3, GAMA0, its volume
  // correction A, the initial energy E0 and relative volume V0, the LCID of card 2.
  double c = 0, s1 = 0, s2 = 0, s3 = 0, gamma0 = 0, a = 0, e0 = 0, v0 = 0;
  std::int64_t lcid = 0;
  Where at, at2; // its two cards
};

struct HourglassCard {
  std::int64_t ihq;
  double qm, q1, q2;
  Where at;
};

struct IdSet {
  std::vector<std::int64_t> ids;                             // listed ids
  std::vector<std::pair<std::int64_t, std::int64_t>> ranges; // _GENERATE ranges
  std::vector<std::int64_t> sets;                            // _ADD: the sets it unites
  Where at;
  std::string keyword; // the keyword that defined it (for messages)
};

struct Spc {
  std::int64_t set = 0, node = 0; // one of them
  std::array<bool, 3> fix{};
  Where at;
  std::string keyword;
  std::int64_t seq = 0; // the card's place among the constraints and motions
};

// *DEFINE_CURVE, scaled and offset: a time history for prescribed motions.
struct CurveCard {
  std::int64_t lcid = 0;
  TimeCurve curve;
  Where at;
};

// *BOUNDARY_PRESCRIBED_MOTION_SET/_NODE: one component of a node set's (a node's)
// velocity or displacement, SF times curve LCID.
struct MotionCard {
  std::int64_t set = 0, node = 0; // one of them
  std::int64_t pid = 0;           // or a rigid part (*BOUNDARY_PRESCRIBED_MOTION_RIGID)
  int dof = 0;                    // 0, 1, 2: x, y, z
  bool rotation = false;          // DOF 5, 6, 7 of a rigid part: its spin about x, y, z
  bool displacement = false;      // VAD 2 (else 0, velocity)
  std::int64_t lcid = 0;
  double sf = 1;
  double birth = 0, death = std::numeric_limits<double>::infinity(); // (DEATH 0: never)
  Where at;
  std::string keyword;
  std::int64_t seq = 0; // the card's place among the constraints and motions
};

// *LOAD_BODY_X/Y/Z: a base acceleration SF times curve LCID along one axis.
struct BodyCard {
  int axis = 0;
  std::int64_t lcid = 0;
  double sf = 1;
  Where at;
  std::string keyword;
};

// *LOAD_NODE_POINT/_SET: a force SF times curve LCID along one axis on a node (each node
// of a set).
struct NodeLoadCard {
  std::int64_t set = 0, node = 0; // one of them
  int dof = 0;                    // 0, 1, 2: x, y, z
  std::int64_t lcid = 0;
  double sf = 1;
  Where at;
  std::string keyword;
};

// *LOAD_SEGMENT (one segment by its nodes) or *LOAD_SEGMENT_SET (a *SET_SEGMENT): a
// pressure SF times curve LCID.
struct SegmentLoadCard {
  std::int64_t set = 0;                // *LOAD_SEGMENT_SET
  std::array<std::int64_t, 4> nodes{}; // *LOAD_SEGMENT: N1-N4 (node ids)
  std::int64_t lcid = 0;
  double sf = 1;
  double arrival = 0;                                     // AT: the pressure acts from then on
  double death = std::numeric_limits<double>::infinity(); // DT of *LOAD_SEGMENT_SET
  Where at;
  std::string keyword;
};

// *SET_SEGMENT: quadrilaterals by their four node ids, each with its card.
struct SegmentSet {
  std::vector<std::array<std::int64_t, 4>> segments;
  std::vector<Where> at;
  Where head;
};

struct VelocityGen {
  int styp; // 1 part set, 2 part, 3 node set, 0: all parts (*INITIAL_VELOCITY with NSID 0),
            // 4: the nodes `nodes` (*INITIAL_VELOCITY_NODE cards of one velocity)
  std::int64_t id;
  std::vector<std::int64_t> nodes; // node ids (styp 4)
  std::vector<Where> node_at;      // their cards
  Vec3 velocity, angular, center;
  bool mass_center = false; // *INITIAL_VELOCITY_RIGID_BODY: about the part's centre of mass
  Where at;
  std::string keyword;
};

struct ContactCard {
  std::int64_t ssid, sstyp;
  std::int64_t msid, mstyp; // the master side of a two-surface form (msid 0: none)
  bool two_surface;
  double fs, fd, dc, vdc, bt, dt, sfs, sfm;
  Where at;
  std::string keyword;
};

struct WallCard {
  std::int64_t nsid, nsidex, boxid;
  double offset, birth, death;
  Vec3 tail, head;
  double fric, wvel;
  Where at;
};

struct Unsupported {
  int count = 0;
  Where first;
};

// ---- the reader ---------------------------------------------------------------------------

class KeywordReader {
public:
  explicit KeywordReader(bool mesh_only) : mesh_only_(mesh_only) {}

  void read(std::vector<Block>& blocks) {
    // Keywords that hold one setting of the whole run: a repeat replaces the earlier one,
    // said in a warning. Decks often *INCLUDE shared controls and override one of them, so
    // a repeat is not an error, but a silent override could hide a forgotten copy.
    static const std::set<std::string> settings{
        "CONTROL_TERMINATION",    "CONTROL_TIMESTEP",       "CONTROL_HOURGLASS", "CONTROL_CONTACT",
        "CONTROL_BULK_VISCOSITY", "DATABASE_BINARY_D3PLOT", "CONTROL_SPH"};
    std::map<std::string, Where> first;
    for (const Block& b : blocks) {
      dispatch(b);
      check_all_taken(b);
      if (mesh_only_ || !settings.count(b.name)) continue;
      const auto [it, fresh] = first.emplace(b.name, where_of(b.head));
      if (!fresh)
        warnings_.push_back(fmt::format("{}: *{} repeats the one at {}; the later one is used",
                                        where_of(b.head).str(), b.name, it->second.str()));
    }
  }

  Mesh mesh() {
    std::vector<std::int64_t> order;
    for (const auto& p : parts_) order.push_back(p.pid);
    std::set<std::int64_t> known(order.begin(), order.end());
    for (const auto& e : elements_)
      if (known.insert(e.pid).second) order.push_back(e.pid);
    return build_mesh(order, false);
  }

  Config config(const std::string& deck_file);

  // The one warning that lists the keywords anvil ignored ("" if none), and an input error
  // that carries it, for an error that stops the read before config() returns it.
  std::string ignored_keywords(const std::string& deck_file) const;
  InputError with_ignored_keywords(const InputError& e, const std::string& deck_file) const;

private:
  // ---- dispatch -------------------------------------------------------------------------

  void dispatch(const Block& b) {
    const std::string& n = b.name;
    if (starts_with(n, "INCLUDE_")) return include_variant(b);
    if (n == "NODE") return node(b);
    if (n == "ELEMENT_SOLID") return element_solid(b);
    if (n == "PART" || n == "PART_CONTACT") return part(b);
    if (n == "SET_NODE" || n == "SET_NODE_LIST" || n == "SET_NODE_TITLE" ||
        n == "SET_NODE_LIST_TITLE")
      return id_set(b, node_sets_, SetForm::list);
    if (n == "SET_NODE_LIST_GENERATE" || n == "SET_NODE_LIST_GENERATE_TITLE")
      return id_set(b, node_sets_, SetForm::generate);
    if (n == "SET_NODE_ADD" || n == "SET_NODE_ADD_TITLE")
      return id_set(b, node_sets_, SetForm::add);
    if (mesh_only_) return;
    if (n == "SET_PART" || n == "SET_PART_LIST" || n == "SET_PART_TITLE" ||
        n == "SET_PART_LIST_TITLE")
      return id_set(b, part_sets_, SetForm::list);
    if (n == "SET_PART_LIST_GENERATE" || n == "SET_PART_LIST_GENERATE_TITLE")
      return id_set(b, part_sets_, SetForm::generate);
    if (n == "SET_PART_ADD" || n == "SET_PART_ADD_TITLE")
      return id_set(b, part_sets_, SetForm::add);
    if (n == "SECTION_SOLID" || n == "SECTION_SOLID_TITLE") return section_solid(b);
    if (n == "SECTION_SPH" || n == "SECTION_SPH_TITLE") return section_sph(b);
    if (n == "ELEMENT_SPH" || n == "ELEMENT_SPH_VOLUME") return element_sph(b);
    if (n == "CONTROL_SPH") return control_sph(b);
    if (starts_with(n, "SECTION_")) return other_with_id(b, other_sections_);
    if (n == "MAT_ELASTIC" || n == "MAT_001" || n == "MAT_ELASTIC_TITLE" || n == "MAT_001_TITLE")
      return mat_elastic(b);
    if (n == "MAT_PLASTIC_KINEMATIC" || n == "MAT_003" || n == "MAT_PLASTIC_KINEMATIC_TITLE" ||
        n == "MAT_003_TITLE")
      return mat_plastic_kinematic(b);
    if (n == "MAT_JOHNSON_COOK" || n == "MAT_015" || n == "MAT_JOHNSON_COOK_TITLE" ||
        n == "MAT_015_TITLE")
      return mat_johnson_cook(b);
    if (n == "BOUNDARY_PRESCRIBED_MOTION_RIGID" || n == "BOUNDARY_PRESCRIBED_MOTION_RIGID_ID")
      return prescribed_motion_rigid(b);
    if (n == "CONSTRAINED_RIGID_BODIES") return constrained_rigid_bodies(b);
    // Keywords that drive, load or shape rigid bodies otherwise: ignoring them would run
    // another model (QA round 29: a driven body ran free), so they are errors.
    for (const char* k : {"BOUNDARY_PRESCRIBED_MOTION_RIGID", "LOAD_RIGID_BODY", "PART_INERTIA",
                          "CONSTRAINED_RIGID_BODIES", "CONSTRAINED_EXTRA_NODES"})
      if (starts_with(n, k))
        throw InputError(where_of(b.head).loc("*" + b.name),
                         fmt::format("*{} is not supported: anvil's rigid bodies (*MAT_RIGID, "
                                     "its CMO = 1 constraints) move under contact, loads and "
                                     "gravity with the mass and inertia of their elements' "
                                     "nodes, driven by *BOUNDARY_PRESCRIBED_MOTION_RIGID(_ID) "
                                     "and started by *INITIAL_VELOCITY_RIGID_BODY",
                                     b.name));
    if (n == "MAT_RIGID" || n == "MAT_020" || n == "MAT_RIGID_TITLE" || n == "MAT_020_TITLE")
      return mat_rigid(b);
    if (n == "MAT_SIMPLIFIED_JOHNSON_COOK" || n == "MAT_098" ||
        n == "MAT_SIMPLIFIED_JOHNSON_COOK_TITLE" || n == "MAT_098_TITLE")
      return mat_simplified_johnson_cook(b);
    if (n == "MAT_PIECEWISE_LINEAR_PLASTICITY" || n == "MAT_024" ||
        n == "MAT_PIECEWISE_LINEAR_PLASTICITY_TITLE" || n == "MAT_024_TITLE")
      return mat_piecewise_linear_plasticity(b);
    if (n == "MAT_NULL" || n == "MAT_009" || n == "MAT_NULL_TITLE" || n == "MAT_009_TITLE")
      return mat_null(b);
    if (starts_with(n, "MAT_")) return other_material(b);
    if (starts_with(n, "EOS_")) return eos(b);
    if (n == "HOURGLASS" || n == "HOURGLASS_TITLE") return hourglass(b);
    if (n == "BOUNDARY_SPC_SET" || n == "BOUNDARY_SPC_SET_ID") return spc(b, true);
    if (n == "BOUNDARY_SPC_NODE" || n == "BOUNDARY_SPC_NODE_ID") return spc(b, false);
    if (n == "BOUNDARY_PRESCRIBED_MOTION_SET" || n == "BOUNDARY_PRESCRIBED_MOTION_SET_ID")
      return prescribed_motion(b, true);
    if (n == "BOUNDARY_PRESCRIBED_MOTION_NODE" || n == "BOUNDARY_PRESCRIBED_MOTION_NODE_ID")
      return prescribed_motion(b, false);
    if (n == "LOAD_BODY_X" || n == "LOAD_BODY_Y" || n == "LOAD_BODY_Z") return body_load(b);
    if (n == "LOAD_NODE_POINT" || n == "LOAD_NODE_SET") return node_load(b, n == "LOAD_NODE_SET");
    if (n == "LOAD_SEGMENT" || n == "LOAD_SEGMENT_ID") return segment_load(b, false);
    if (n == "LOAD_SEGMENT_SET" || n == "LOAD_SEGMENT_SET_ID") return segment_load(b, true);
    if (n == "SET_SEGMENT" || n == "SET_SEGMENT_TITLE") return segment_set(b);
    if (n == "LOAD_BODY_PARTS")
      throw InputError(b.head.where("*LOAD_BODY_PARTS"),
                       "*LOAD_BODY_PARTS is not supported: anvil's body loads act on every "
                       "part and particle set, so the run would load parts this deck leaves "
                       "unloaded");
    if (n == "DEFINE_CURVE" || n == "DEFINE_CURVE_TITLE") {
      Cursor(b).skip_rest(); // read when a motion names it
      curve_blocks_.push_back(&b);
      return;
    }
    if (n == "INITIAL_VELOCITY_GENERATION") return velocity_generation(b);
    if (n == "INITIAL_VELOCITY") return initial_velocity(b);
    if (n == "INITIAL_VELOCITY_NODE") return initial_velocity_node(b);
    if (n == "INITIAL_VELOCITY_RIGID_BODY") return initial_velocity_rigid_body(b);
    if (contact_form(n)) return contact(b);
    if (n == "CONTROL_CONTACT") return control_contact(b);
    if (n == "RIGIDWALL_PLANAR" || n == "RIGIDWALL_PLANAR_ID") return rigidwall(b);
    if (n == "CONTROL_TERMINATION") return control_termination(b);
    if (n == "CONTROL_TIMESTEP") return control_timestep(b);
    if (n == "CONTROL_HOURGLASS") return control_hourglass(b);
    if (n == "CONTROL_BULK_VISCOSITY") return control_bulk_viscosity(b);
    if (n == "DATABASE_BINARY_D3PLOT") return d3plot(b);
    if (n == "DATABASE_BINARY_D3DUMP" || n == "DATABASE_BINARY_RUNRSF") return restart_dump(b);
    if (n == "DATABASE_GLSTAT" || n == "DATABASE_NODOUT" || n == "DATABASE_ELOUT")
      return history_interval(b);
    if (n == "DATABASE_MATSUM") {
      part_energies_ = true; // the parts' energies in history.csv
      return history_interval(b);
    }
    if (n == "DATABASE_HISTORY_NODE") return history_nodes(b, false);
    if (n == "DATABASE_HISTORY_NODE_SET") return history_nodes(b, true);
    if (n == "DATABASE_HISTORY_NODE_ID") return history_nodes_id(b);
    if (n == "DATABASE_HISTORY_SOLID") return history_solids(b, false);
    if (n == "DATABASE_HISTORY_SOLID_ID") return history_solids(b, true);
    if (n == "TITLE") {
      Cursor c(b);
      title_ = text_card(c.next());
      return;
    }
    // Output and performance controls that change nothing anvil computes. Other
    // *DATABASE_HISTORY_... keywords ask for output anvil does not write (shell, beam or
    // local-system histories, sets of solids): listed as ignored, so that their absence
    // is no surprise.
    if ((starts_with(n, "DATABASE_") && !starts_with(n, "DATABASE_HISTORY_")) ||
        n == "CONTROL_ENERGY" || n == "CONTROL_OUTPUT" || n == "CONTROL_CPU" ||
        n == "CONTROL_PARALLEL" || starts_with(n, "CONTROL_MPP_") || n == "COMMENT")
      return;
    auto& u = unsupported_[n];
    if (u.count++ == 0) u.first = where_of(b.head);
  }

  // *INCLUDE_TRANSFORM, *INCLUDE_PATH, ...: anvil reads plain *INCLUDE only. Ignoring one
  // would leave out what its file holds (parts, nodes, elements) and run another model.
  [[noreturn]] static void include_variant(const Block& b) {
    std::string file;
    for (const auto& l : b.lines)
      if (!trim(l.text).empty()) {
        file = fmt::format(" ('{}')", shown(trim(l.text)));
        break;
      }
    throw InputError(b.head.where("*" + b.name),
                     fmt::format("*{}{} is not supported: anvil reads plain *INCLUDE only, and "
                                 "leaving the file out would change the model{}",
                                 b.name, file,
                                 starts_with(b.name, "INCLUDE_PATH")
                                     ? " (name included files relative to the including file)"
                                     : " (write the transformed or converted mesh to a file and "
                                       "*INCLUDE that)"));
  }

  // The title card of a _TITLE keyword (skipped), then the first card.
  static void skip_title(const Block& b, Cursor& c) {
    if (ends_with(b.name, "_TITLE")) c.next();
  }

  // ---- mesh -----------------------------------------------------------------------------

  // The message for a blank first id of a mesh card (`field` of keyword b): its width, and
  // the wider formats when it is the standard one.
  static std::string blank_id(const Block& b, std::string_view field) {
    if (b.long_format || b.i10)
      return fmt::format("{} is blank: *{}'s first field is {} characters wide here", field, b.name,
                         b.long_format ? 20 : 10);
    return fmt::format("{} is blank: *{}'s first field is 8 characters wide (for 10 characters "
                       "give *KEYWORD I10=Y or '*{} %')",
                       field, b.name, b.name);
  }

  void node(const Block& b) {
    Cursor c(b);
    while (auto l = c.next_record()) {
      const Card card(b, *l, {8, 16, 16, 16, 8, 8});
      const std::int64_t nid = card.integer(0, "NID", 0);
      if (card.blank(0)) card.fail("NID", blank_id(b, "NID"));
      if (nid <= 0) card.fail("NID", fmt::format("NID must be a positive node id, found {}", nid));
      Vec3 x;
      try {
        x = Vec3{card.real(1, "X"), card.real(2, "Y"), card.real(3, "Z")};
      } catch (const InputError&) {
        // An id wider than the NID field (the commonest slip when moving a large model)
        // shifts the coordinates: say so rather than blame X.
        if (card.runs_into_next(0)) card.fail("NID", wide_id(card, 0, "NID", "X"));
        throw;
      }
      const std::int64_t tc = card.integer(4, "TC", 0);
      if (tc < 0 || tc > 7)
        card.fail("TC", fmt::format("TC must be 0 to 7 (translational constraint), found {}", tc));
      const auto [it, fresh] = node_index_.emplace(nid, static_cast<std::int64_t>(nodes_.size()));
      if (!fresh)
        card.fail("NID", fmt::format("node {} is defined twice (first at {})", nid,
                                     node_at_[it->second].str()));
      nodes_.push_back(x);
      node_at_.push_back(where_of(*l));
      node_ids_.push_back(nid);
      if (tc != 0) node_tc_.push_back({nid, static_cast<int>(tc), where_of(*l), card_seq_++});
    }
  }

  void element_solid(const Block& b) {
    Cursor c(b);
    while (auto l = c.next_record()) {
      const Card first(b, *l, {8, 8, 8, 8, 8, 8, 8, 8, 8, 8});
      RawElement e{};
      e.eid = first.integer(0, "EID", 0);
      e.pid = first.integer(1, "PID", 0);
      e.at = where_of(*l);
      if (first.blank(0)) first.fail("EID", blank_id(b, "EID"));
      if (e.eid <= 0) first.fail("EID", fmt::format("EID must be a positive id, found {}", e.eid));
      if (e.pid <= 0)
        first.fail("PID", fmt::format("element {}: PID must be a positive part id, found {}", e.eid,
                                      e.pid));
      // The old one-line form (EID PID N1..N8), or EID PID then a card of N1..N10.
      bool one_line = false;
      for (int i = 2; i < 10; ++i) one_line = one_line || !first.blank(i);
      std::optional<Card> second;
      if (!one_line) {
        const auto l2 = c.next_record();
        if (!l2)
          first.fail("N1",
                     fmt::format("element {}: the card with its nodes N1-N8 is missing", e.eid));
        second.emplace(b, *l2, std::initializer_list<int>{8, 8, 8, 8, 8, 8, 8, 8, 8, 8});
      }
      const Card& nc = one_line ? first : *second;
      const int base = one_line ? 2 : 0;
      int given = 0;
      for (int a = 0; a < 8; ++a) {
        const std::string name = fmt::format("N{}", a + 1);
        e.nodes[a] = nc.integer(base + a, name, 0);
        if (e.nodes[a] < 0)
          nc.fail(name, fmt::format("element {}: {} must be a positive node id, found {}", e.eid,
                                    name, e.nodes[a]));
        if (e.nodes[a] > 0) ++given;
      }
      if (!one_line && (nc.integer(8, "N9", 0) != 0 || nc.integer(9, "N10", 0) != 0))
        nc.fail("N9", fmt::format("element {} has more than 8 nodes; anvil reads 8-node "
                                  "solids only (no 10-node tetrahedra)",
                                  e.eid));
      if (given < 8)
        nc.fail(fmt::format("N{}", given + 1),
                fmt::format("element {} has {} nodes; anvil reads 8-node solids (write a "
                            "tetrahedron N1 N2 N3 N4 N4 N4 N4 N4, a pentahedron N1 N2 N3 N4 N5 "
                            "N5 N6 N6, as LS-DYNA does)",
                            e.eid, given));
      int corner = 0;
      if (const std::string why = canonical_hex(e.nodes, e.eid, &corner); !why.empty())
        nc.fail(fmt::format("N{}", corner + 1), why);
      const auto [it, fresh] = element_index_.emplace(e.eid, elements_.size());
      if (!fresh)
        first.fail("EID", fmt::format("element {} is defined twice (first at {})", e.eid,
                                      elements_[it->second].at.str()));
      elements_.push_back(e);
    }
  }

  void part(const Block& b) {
    Cursor c(b);
    while (!c.done()) {
      // Each part is a heading card (free text, possibly blank) and a card of ids.
      const Line head = c.next();
      if (c.done())
        throw InputError(head.where(b.key("PID")),
                         "the part card (PID SECID MID ...) after the heading is missing");
      const Line l = c.next();
      const Card card(b, l, {10, 10, 10, 10, 10, 10, 10, 10});
      PartCard p{
          card.integer(0, "PID", 0), card.id(1, "SECID"), card.id(2, "MID"), card.id(3, "EOSID"),
          card.id(4, "HGID"),        text_card(head),     where_of(l)};
      if (p.pid <= 0)
        card.fail("PID", fmt::format("PID must be a positive part id, found {}", p.pid));
      if (!mesh_only_) {
        if (p.secid == 0) card.fail("SECID", fmt::format("part {} has no section (SECID)", p.pid));
        if (p.mid == 0) card.fail("MID", fmt::format("part {} has no material (MID)", p.pid));
      }
      for (const auto& q : parts_)
        if (q.pid == p.pid)
          card.fail("PID",
                    fmt::format("part {} is defined twice (first at {})", p.pid, q.at.str()));
      // *PART_CONTACT: a card of the part's contact properties (FS, FD, DC, VC, OPTT, SFT,
      // SSF, CPARM8), which LS-DYNA's contacts use where they ask for part values (FS = -1,
      // SFT, SSF): anvil's one contact takes its own, so any set is said not to be used.
      if (b.name == "PART_CONTACT" && !mesh_only_) {
        const Line lc = c.next();
        const Card cc(b, lc, {10, 10, 10, 10, 10, 10, 10, 10});
        static const char* const fields[] = {"FS",   "FD",  "DC",  "VC",
                                             "OPTT", "SFT", "SSF", "CPARM8"};
        for (int i = 0; i < 8; ++i)
          if (!cc.blank(i) && cc.real(i, fields[i]) != 0) {
            warnings_.push_back(fmt::format("{}: *PART_CONTACT: part {}'s contact properties "
                                            "are not used: anvil's contact takes the friction "
                                            "and penalty scale of its *CONTACT_ card",
                                            where_of(lc).str(), p.pid));
            break;
          }
      } else if (b.name == "PART_CONTACT") {
        c.next();
      }
      parts_.push_back(std::move(p));
    }
  }

  enum class SetForm { list, generate, add };
  void id_set(const Block& b, std::map<std::int64_t, IdSet>& sets, SetForm form) {
    const bool generate = form == SetForm::generate;
    Cursor c(b);
    skip_title(b, c);
    const Line l = c.next();
    const Card head(b, l, {10, 10, 10, 10, 10, 10});
    const std::int64_t sid = head.integer(0, "SID", 0);
    if (sid <= 0) head.fail("SID", fmt::format("SID must be a positive set id, found {}", sid));
    IdSet s;
    s.at = where_of(l);
    s.keyword = b.name;
    while (auto r = c.next_record()) {
      const Card card(b, *r, {10, 10, 10, 10, 10, 10, 10, 10}, Card::Extra::keep);
      if (form == SetForm::add) {
        for (int k = 0; k < card.size(); ++k)
          if (const auto id = card.id(k, fmt::format("DSID{}", k + 1)); id != 0)
            s.sets.push_back(id);
      } else if (generate) {
        for (int k = 0; k < card.size(); k += 2) {
          const auto lo = card.id(k, fmt::format("B{}BEG", k / 2 + 1));
          const auto hi = card.id(k + 1, fmt::format("B{}END", k / 2 + 1));
          if (lo == 0 && hi == 0) continue;
          if (lo == 0 || hi < lo)
            card.fail(fmt::format("B{}END", k / 2 + 1),
                      fmt::format("the range {} to {} is empty or starts at 0", lo, hi));
          s.ranges.emplace_back(lo, hi);
        }
      } else {
        for (int k = 0; k < card.size(); ++k)
          if (const auto id = card.id(k, fmt::format("ID{}", k + 1)); id != 0) s.ids.push_back(id);
      }
    }
    const auto [it, fresh] = sets.emplace(sid, std::move(s));
    if (!fresh)
      head.fail("SID", fmt::format("set {} of this kind is defined twice (first at {})", sid,
                                   it->second.at.str()));
  }

  // ---- sections, materials, equations of state, hourglass -------------------------------

  void section_solid(const Block& b) {
    Cursor c(b);
    while (!c.done()) {
      skip_title(b, c);
      const Line l = c.next();
      const Card card(b, l, {10, 10, 10});
      const std::int64_t secid = card.integer(0, "SECID", 0);
      if (secid <= 0)
        card.fail("SECID", fmt::format("SECID must be a positive id, found {}", secid));
      const std::int64_t elform = card.integer(1, "ELFORM", 1);
      if (elform >= 101 && elform <= 105)
        card.fail("ELFORM", fmt::format("ELFORM {} is a user element; anvil has its one-point "
                                        "hexahedron (ELFORM 1) only",
                                        elform));
      add_section(card, secid, SectionCard{elform, b.name, where_of(l)});
    }
  }

  void add_section(const Card& card, std::int64_t secid, SectionCard s) {
    if (const auto it = sph_sections_.find(secid); it != sph_sections_.end())
      card.fail("SECID", fmt::format("section {} is defined twice (first at {})", secid,
                                     it->second.at.str()));
    const auto [it, fresh] = sections_.emplace(secid, std::move(s));
    if (!fresh)
      card.fail("SECID", fmt::format("section {} is defined twice (first at {})", secid,
                                     it->second.at.str()));
  }

  // *SECTION_SPH: SECID, CSLH, HMIN, HMAX, SPHINI, DEATH, START, SPHKERN (one card a
  // section): the smoothing length h0 = CSLH times the largest distance from a particle to
  // its nearest neighbour, or SPHINI; h stays within [HMIN, HMAX] h0.
  void section_sph(const Block& b) {
    Cursor c(b);
    while (!c.done()) {
      skip_title(b, c);
      const Line l = c.next();
      const Card card(b, l, {10, 10, 10, 10, 10, 10, 10, 10});
      const std::int64_t secid = card.integer(0, "SECID", 0);
      if (secid <= 0)
        card.fail("SECID", fmt::format("SECID must be a positive id, found {}", secid));
      SphSectionCard sc{card.real(1, "CSLH"), card.real(2, "HMIN"), card.real(3, "HMAX"),
                        card.real(4, "SPHINI"), where_of(l)};
      // LS-DYNA's defaults: CSLH 1.2, HMIN 0.2, HMAX 2.0 (a blank or 0 field).
      if (sc.cslh == 0) sc.cslh = 1.2;
      if (sc.hmin == 0) sc.hmin = 0.2;
      if (sc.hmax == 0) sc.hmax = 2.0;
      if (!(sc.cslh >= 0.8 && sc.cslh <= 3))
        card.fail("CSLH", fmt::format("CSLH must be between 0.8 and 3 (LS-DYNA advises 1.05 to "
                                      "1.3), found {}",
                                      sc.cslh));
      if (!(sc.hmin > 0 && sc.hmin <= 1))
        card.fail("HMIN", fmt::format("HMIN must be in (0, 1], found {}", sc.hmin));
      if (!(sc.hmax >= 1))
        card.fail("HMAX", fmt::format("HMAX must be at least 1, found {}", sc.hmax));
      if (sc.sphini < 0) card.fail("SPHINI", "SPHINI must not be negative");
      const double death = card.real(5, "DEATH");
      if (death != 0 && death < 1e20)
        sph_notes_.push_back(fmt::format("{}: section {}: DEATH {} is not used: anvil's "
                                         "particles live to the end of the run",
                                         where_of(l).str(), secid, death));
      if (card.real(6, "START") != 0)
        sph_notes_.push_back(fmt::format("{}: section {}: START is not used: anvil's particles "
                                         "act from t = 0",
                                         where_of(l).str(), secid));
      if (const std::int64_t k = card.integer(7, "SPHKERN", 0); k != 0)
        sph_notes_.push_back(fmt::format("{}: section {}: SPHKERN {} is not anvil's: its "
                                         "particles use the cubic B-spline kernel (SPHKERN 0)",
                                         where_of(l).str(), secid, k));
      if (const auto it = sections_.find(secid); it != sections_.end())
        card.fail("SECID", fmt::format("section {} is defined twice (first at {})", secid,
                                       it->second.at.str()));
      const auto [it, fresh] = sph_sections_.emplace(secid, sc);
      if (!fresh)
        card.fail("SECID", fmt::format("section {} is defined twice (first at {})", secid,
                                       it->second.at.str()));
    }
  }

  // *ELEMENT_SPH (_VOLUME): any number of cards NID, PID, MASS, NEND.
  void element_sph(const Block& b) {
    const bool volume = b.name == "ELEMENT_SPH_VOLUME";
    Cursor c(b);
    while (auto l = c.next_record()) {
      const Card card(b, *l, {8, 8, 16, 8});
      RawSph e{card.integer(0, "NID", 0),
               card.id(3, "NEND"),
               card.integer(1, "PID", 0),
               0,
               0,
               where_of(*l)};
      if (card.blank(0)) card.fail("NID", blank_id(b, "NID"));
      card.no_fields_after(4); // NID, PID, MASS, NEND: nothing after column 40
      if (e.nid <= 0)
        card.fail("NID", fmt::format("NID must be a positive node id, found {}", e.nid));
      if (e.pid <= 0)
        card.fail("PID", fmt::format("particle {}: PID must be a positive part id, found {}", e.nid,
                                     e.pid));
      if (e.nend != 0 && e.nend < e.nid)
        card.fail("NEND", fmt::format("NEND {} is below NID {}", e.nend, e.nid));
      const double m = card.real(2, "MASS");
      if (m == 0)
        card.fail("MASS", fmt::format("particle {} has no mass: give its mass, or its volume as "
                                      "a negative MASS (or with *ELEMENT_SPH_VOLUME)",
                                      e.nid));
      if (volume && m < 0)
        card.fail("MASS", fmt::format("particle {}: with *ELEMENT_SPH_VOLUME, MASS is the "
                                      "particle's volume and must be positive",
                                      e.nid));
      (volume || m < 0 ? e.volume : e.mass) = std::abs(m);
      sph_elements_.push_back(e);
    }
  }

  // *CONTROL_SPH: card 1 NCBS, BOXID, DT, IDIM, NMNEIGH, FORM, START, MAXV; the optional
  // cards that follow are taken, not read.
  void control_sph(const Block& b) {
    Cursor c(b);
    const Line l = c.next();
    const Card card(b, l, {10, 10, 10, 10, 10, 10, 10, 10});
    // Cards 2 and on (CONT, DERIV, INI, ISHOW, IEROD, ICONT, IAVIS, ISYMP; then card 3's,
    // named by place): taken; the fields set are said not to be read (CONT = 1, IEROD,
    // IAVIS change the run in LS-DYNA).
    sph_control_notes_.clear();
    static const char* const card2[] = {"CONT",  "DERIV", "INI",   "ISHOW",
                                        "IEROD", "ICONT", "IAVIS", "ISYMP"};
    for (int k = 2; !c.done(); ++k) {
      const Line lk = c.next();
      const Card ck(b, lk, {10, 10, 10, 10, 10, 10, 10, 10}, Card::Extra::keep);
      std::string set; // the fields this card sets
      for (int i = 0; i < ck.size(); ++i) {
        const std::string name =
            k == 2 && i < 8 ? std::string(card2[i]) : fmt::format("card{}.field{}", k, i + 1);
        if (!ck.blank(i) && ck.real(i, name) != 0) set += (set.empty() ? "" : ", ") + name;
      }
      if (!set.empty())
        sph_control_notes_.push_back(fmt::format(
            "{}: *CONTROL_SPH card {} sets {}, which anvil does not read (its particle sets all "
            "interact, are not eroded, and take the Monaghan viscosity)",
            where_of(lk).str(), k, set));
    }
    control_sph_at_ = where_of(l);
    const std::int64_t idim = card.integer(3, "IDIM", 0);
    if (idim != 0 && idim != 3)
      card.fail("IDIM", fmt::format("IDIM {} is not supported: anvil reads three-dimensional "
                                    "particle models (IDIM 3) from keyword decks",
                                    idim));
    const std::int64_t form = card.integer(5, "FORM", 0);
    sph_corrected_ = form == 1;
    const std::string at = where_of(l).str();
    if (form != 0 && form != 1)
      sph_control_notes_.push_back(fmt::format(
          "{}: *CONTROL_SPH FORM {} is not anvil's: its particles use the standard form "
          "(FORM 0) with the Monaghan-Gingold viscosity (docs/sph.md)",
          at, form));
    if (card.id(1, "BOXID") != 0)
      sph_control_notes_.push_back(fmt::format(
          "{}: *CONTROL_SPH BOXID is not used: anvil computes every particle everywhere", at));
    if (const double dt = card.real(2, "DT"); dt != 0 && dt < 1e20)
      sph_control_notes_.push_back(fmt::format(
          "{}: *CONTROL_SPH DT {} is not used: anvil computes the particles to the end", at, dt));
    if (card.real(6, "START") != 0)
      sph_control_notes_.push_back(
          fmt::format("{}: *CONTROL_SPH START is not used: the particles act from t = 0", at));
    if (const double v = card.real(7, "MAXV"); v != 0 && v < 1e15)
      sph_control_notes_.push_back(fmt::format(
          "{}: *CONTROL_SPH MAXV {} is not used: anvil keeps every particle, however fast", at, v));
  }

  // A keyword anvil does not model whose first field is an id others may refer to
  // (*SECTION_SHELL): remembered so that a reference to it gets a precise message.
  void other_with_id(const Block& b, std::map<std::int64_t, SectionCard>& into) {
    Cursor c(b);
    skip_title(b, c);
    if (c.done()) return unsupported(b);
    const Line l = c.next();
    const Card card(b, l, {10}, Card::Extra::keep);
    std::int64_t id = 0;
    try {
      id = card.integer(0, "ID", 0);
    } catch (const InputError&) {
      id = 0; // not even an id: listed as unsupported all the same
    }
    if (id > 0) into.emplace(id, SectionCard{0, b.name, where_of(l)});
    c.skip_rest(); // the keyword is listed as ignored, whatever its cards
    unsupported(b);
  }

  // Up to `most` optional cards that LS-DYNA allows after a keyword's cards and anvil does
  // not read (*CONTACT_... optional cards A-G, the second card of *CONTROL_TIMESTEP). With
  // `warn`, a card that sets anything (a field not blank or zero) gets a warning naming
  // it; more cards than `most` remain for check_all_taken to refuse.
  void optional_cards(const Block& b, Cursor& c, int most, bool warn) {
    for (int k = 0; k < most && !c.done(); ++k) {
      const Line l = c.next();
      if (!warn || !sets_something(l.text)) continue;
      warnings_.push_back(fmt::format("{}: an optional card of *{} is ignored (anvil does not "
                                      "read it): '{}'",
                                      where_of(l).str(), b.name, shown(trim(l.text))));
    }
  }

  // Whether a card holds a field other than blank or zero (in either card format).
  static bool sets_something(std::string_view text) {
    std::string field;
    auto nonzero = [&] {
      if (field.empty()) return false;
      char* end = nullptr;
      const double v = std::strtod(field.c_str(), &end);
      return *end != '\0' || v != 0;
    };
    for (const char ch : text) {
      if (ch == ' ' || ch == ',' || ch == '\t' || ch == '\r') {
        if (nonzero()) return true;
        field.clear();
      } else {
        field += ch;
      }
    }
    return nonzero();
  }

  void unsupported(const Block& b) {
    auto& u = unsupported_[b.name];
    if (u.count++ == 0) u.first = where_of(b.head);
  }

  // The MID of a material card; an error unless positive.
  static std::int64_t material_id(const Card& card) {
    const std::int64_t mid = card.integer(0, "MID", 0);
    if (mid <= 0) card.fail("MID", fmt::format("MID must be a positive id, found {}", mid));
    return mid;
  }

  void add_material(const Card& card, std::int64_t mid, MaterialCard m) {
    const auto [it, fresh] = materials_.emplace(mid, std::move(m));
    if (!fresh)
      card.fail("MID", fmt::format("material {} is defined twice (first at {})", mid,
                                   it->second.at.str()));
  }

  // Density, Young's modulus and Poisson's ratio with LS-DYNA's field names in messages.
  static void elastic_fields(const Card& card, ParamValues& p, int ro, int e, int pr) {
    p["density"] = card.real(ro, "RO");
    p["youngs_modulus"] = card.real(e, "E");
    p["poissons_ratio"] = card.real(pr, "PR");
    if (!(p["density"] > 0)) card.fail("RO", "the density RO must be positive");
    if (!(p["youngs_modulus"] > 0)) card.fail("E", "Young's modulus E must be positive");
    if (!(p["poissons_ratio"] > -1 && p["poissons_ratio"] < 0.5))
      card.fail("PR", fmt::format("Poisson's ratio PR = {} is impossible: must be in (-1, 0.5)",
                                  p["poissons_ratio"]));
  }

  void mat_elastic(const Block& b) {
    Cursor c(b);
    skip_title(b, c);
    const Line l = c.next();
    const Card card(b, l, {10, 10, 10, 10, 10, 10, 10});
    const std::int64_t mid = material_id(card);
    MaterialCard m = material_card(b, "elastic", l);
    elastic_fields(card, m.params, 1, 2, 3);
    add_material(card, mid, std::move(m));
  }

  // *MAT_NULL: MID, RO, PC, MU, TEROD, CEROD, YM, PR: anvil's `fluid` (particles only),
  // density RO, viscosity MU; its bulk modulus and pressure come from the part's
  // *EOS_GRUNEISEN (config()). PC, TEROD, CEROD: warned of when set; YM, PR (the contact
  // stiffness of null shells and beams) not read.
  void mat_null(const Block& b) {
    Cursor c(b);
    skip_title(b, c);
    const Line l = c.next();
    const Card card(b, l, {10, 10, 10, 10, 10, 10, 10, 10});
    const std::int64_t mid = material_id(card);
    MaterialCard m = material_card(b, "fluid", l);
    const double rho = card.real(1, "RO");
    if (!(rho > 0)) card.fail("RO", fmt::format("RO must be positive, found {}", rho));
    m.params["density"] = rho;
    const double mu = card.real(3, "MU");
    if (mu < 0) card.fail("MU", fmt::format("MU must not be negative, found {}", mu));
    m.params["viscosity"] = mu;
    m.params["bulk_from_eos"] = 1; // completed per part in config()
    if (card.real(2, "PC") != 0)
      m.notes.push_back(fmt::format("{}: material {}: PC (a pressure cutoff) is not modelled: "
                                    "anvil's fluid carries tension",
                                    where_of(l).str(), mid));
    if (card.real(4, "TEROD") != 0 || card.real(5, "CEROD") != 0)
      m.notes.push_back(fmt::format("{}: material {}: TEROD, CEROD (erosion) are not used: "
                                    "anvil's particles do not erode",
                                    where_of(l).str(), mid));
    add_material(card, mid, std::move(m));
  }

  void mat_plastic_kinematic(const Block& b) {
    Cursor c(b);
    skip_title(b, c);
    const Line l = c.next();
    const Card card(b, l, {10, 10, 10, 10, 10, 10, 10});
    const std::int64_t mid = material_id(card);
    MaterialCard m = material_card(b, "j2_plasticity", l);
    elastic_fields(card, m.params, 1, 2, 3);
    const double E = m.params["youngs_modulus"];
    bilinear_hardening(card, E, "", m);
    const double beta = card.real(6, "BETA");
    if (!(beta >= 0 && beta <= 1)) card.fail("BETA", "BETA must be between 0 and 1");
    if (beta < 1)
      m.notes.push_back(fmt::format(
          "{}: material {}: BETA = {} asks for {} hardening; anvil hardens "
          "isotropically only and uses BETA = 1 (same yield curve in monotonic loading, "
          "no Bauschinger effect)",
          m.at.str(), mid, beta, beta == 0 ? "kinematic" : "mixed"));
    const Line l2 = c.next();
    const Card card2(b, l2, {10, 10, 10, 10});
    // Cowper-Symonds: anvil's piecewise_linear_plasticity in its bilinear form.
    if (cowper_symonds(card2, 0, "SRC", 1, "SRP", m)) m.model = "piecewise_linear_plasticity";
    rate_form(card2, 3, mid, m);
    failure_strain(card2, 2, "FS", m);
    add_material(card, mid, std::move(m));
  }

  // SIGY and ETAN (fields 4 and 5) of *MAT_PLASTIC_KINEMATIC and *MAT_PIECEWISE_LINEAR_
  // PLASTICITY into m: the yield stress and, for linear hardening in the uniaxial curve
  // (slope ETAN), the plastic hardening modulus H = E ETAN / (E - ETAN) in terms of
  // plastic strain. `or_else` ends the SIGY message (the card's other ways to give it).
  static void bilinear_hardening(const Card& card, double E, std::string_view or_else,
                                 MaterialCard& m) {
    const double sigy = card.real(4, "SIGY", 0), etan = card.real(5, "ETAN", 0);
    if (!(sigy > 0))
      card.fail("SIGY", fmt::format("the yield stress SIGY must be positive{}", or_else));
    if (!(etan >= 0 && etan < E))
      card.fail("ETAN",
                fmt::format("the tangent modulus ETAN = {} must be in [0, E = {})", etan, E));
    m.params["yield_stress"] = sigy;
    m.params["hardening_modulus"] = etan * E / (E - etan);
  }

  // A, B, N, C (fields 0-3 of a Johnson-Cook card's second card) into m: the strength law
  // (A + B ep^n) (1 + C ln rate*) of *MAT_JOHNSON_COOK and *MAT_SIMPLIFIED_JOHNSON_COOK.
  static void johnson_cook_strength(const Card& c2, MaterialCard& m) {
    const double A = c2.real(0, "A"), B = c2.real(1, "B"), n = c2.real(2, "N"), C = c2.real(3, "C");
    if (!(A > 0)) c2.fail("A", "the yield stress A must be positive");
    if (B < 0) c2.fail("B", "B must not be negative");
    if (B > 0 && !(n > 0)) c2.fail("N", "the hardening exponent N must be positive");
    if (C < 0) c2.fail("C", "C must not be negative");
    m.params["A"] = A;
    m.params["B"] = B;
    m.params["n"] = B > 0 ? n : 1; // no hardening: the exponent does not matter
    m.params["C"] = C;
  }

  // The Cowper-Symonds constants C and P of a material card into m; true when they turn
  // the rate effect on (C = 0: LS-DYNA's "rate effects are not considered").
  static bool cowper_symonds(const Card& card, int ic, const char* c_name, int ip,
                             const char* p_name, MaterialCard& m) {
    const double C = card.real(ic, c_name, 0), P = card.real(ip, p_name, 0);
    if (C < 0)
      card.fail(c_name, fmt::format("the strain-rate constant {} must not be negative", c_name));
    if (C == 0) return false;
    if (!(P > 0))
      card.fail(p_name, fmt::format("the Cowper-Symonds exponent {} must be positive when {} = {} "
                                    "turns the rate effect on",
                                    p_name, c_name, C));
    m.params["cowper_symonds_C"] = C;
    m.params["cowper_symonds_p"] = P;
    return true;
  }

  // VP, the rate form of MAT_003 and MAT_024: anvil scales the yield stress by the
  // Cowper-Symonds factor of the equivalent strain rate (VP = 0); the viscoplastic forms
  // are replaced by it with a warning, only where a rate law is on.
  static void rate_form(const Card& card, int field, std::int64_t mid, MaterialCard& m) {
    const double vp = card.real(field, "VP", 0);
    if (vp != -1 && vp != 0 && vp != 1 && vp != 3)
      card.fail("VP", fmt::format("VP = {} is not one of LS-DYNA's -1, 0, 1, 3", vp));
    if (vp != 0 && vp != -1 && m.params.count("cowper_symonds_C"))
      m.notes.push_back(fmt::format("{}: material {}: VP = {} (the viscoplastic form of the rate "
                                    "law) is replaced by anvil's scaled yield stress (VP = 0)",
                                    m.at.str(), mid, vp));
  }

  // FS of MAT_003, FAIL of MAT_024, PSFAIL of MAT_098: the effective plastic strain at
  // which an element is deleted, anvil's part key erosion.plastic_strain for every part of
  // the material (0, blank, and LS-DYNA's "never" defaults 1e17 and 1e20 are no failure).
  static void failure_strain(const Card& card, int field, const char* name, MaterialCard& m) {
    const double strain = card.real(field, name, 0);
    if (strain < 0)
      card.fail(name, fmt::format("{} = {}: a negative value (LS-DYNA's other failure forms, "
                                  "such as MAT_024's user failure subroutine) is not supported: "
                                  "give the effective plastic strain at failure, or 0 for none",
                                  name, strain));
    if (strain == 0 || strain >= 1e16) return;
    m.failure_strain = strain;
  }

  // MID, RO, E, PR, N, COUPLE, M, ALIAS; CMO, CON1, CON2; LCO or A1-A6 (LS-DYNA manual,
  // *MAT_RIGID): the parts that use it are rigid bodies; RO gives their mass, E and PR
  // their contact stiffness (as in LS-DYNA: realistic values). Constraints of the body
  // (CMO with CON1, CON2) are not supported: an error rather than a free body.
  void mat_rigid(const Block& b) {
    Cursor c(b);
    skip_title(b, c);
    const Line l = c.next();
    const Card c1(b, l, {10, 10, 10, 10, 10, 10, 10, 10});
    const std::int64_t mid = material_id(c1);
    MaterialCard m = material_card(b, "elastic", l);
    m.rigid = true;
    elastic_fields(c1, m.params, 1, 2, 3);
    const Line l2 = c.next();
    const Card c2(b, l2, {10, 10, 10});
    // CMO = 1: CON1, CON2 hold the translations and rotations in global axes (anvil's
    // `fix` of the body); CMO = -1 (a local system) is not supported; CMO = 0: none.
    const double cmo = c2.real(0, "CMO", 0);
    const double con1 = c2.real(1, "CON1", 0), con2 = c2.real(2, "CON2", 0);
    if (cmo == -1 && (con1 != 0 || con2 != 0))
      c2.fail("CMO", "CMO = -1 (constraints in a local system, VEC) is not supported: give "
                     "CMO = 1 (global axes)");
    if (cmo != 0 && cmo != 1 && cmo != -1) c2.fail("CMO", "CMO must be -1, 0 or 1");
    for (const auto& [value, name] : {std::pair{con1, "CON1"}, {con2, "CON2"}})
      if (value != std::floor(value) || value < 0 || value > 7)
        c2.fail(name, fmt::format("{} must be 0-7 (none, x, y, z, xy, yz, zx, all) with "
                                  "CMO = 1, found {}",
                                  name, value));
    if (cmo == 1) {
      m.con1 = static_cast<int>(con1);
      m.con2 = static_cast<int>(con2);
    } else if (con1 != 0 || con2 != 0) {
      m.notes.push_back(fmt::format("{}: material {}: CON1 and CON2 hold nothing with CMO = 0 "
                                    "(LS-DYNA's \"no constraints\"): give CMO = 1",
                                    where_of(l2).str(), mid));
    }
    c.next(); // LCO or A1-A6: the local constraint directions, unused
    add_material(c1, mid, std::move(m));
  }

  // MID, RO, E, PR, VP; A, B, N, C, PSFAIL, SIGMAX, SIGSAT, EPSO (LS-DYNA manual,
  // *MAT_SIMPLIFIED_JOHNSON_COOK): anvil's johnson_cook without its thermal terms, SIGMAX
  // and SIGSAT its caps (LS-DYNA's defaults, 1e28, are none).
  void mat_simplified_johnson_cook(const Block& b) {
    Cursor c(b);
    skip_title(b, c);
    const Line l = c.next();
    const Card c1(b, l, {10, 10, 10, 10, 10});
    const std::int64_t mid = material_id(c1);
    MaterialCard m = material_card(b, "johnson_cook", l);
    elastic_fields(c1, m.params, 1, 2, 3);
    if (c1.real(4, "VP", 0) != 0)
      m.notes.push_back(fmt::format("{}: material {}: VP = {} (the viscoplastic rate form) is "
                                    "replaced by anvil's scaled yield stress (VP = 0)",
                                    m.at.str(), mid, c1.real(4, "VP", 0)));
    const Line l2 = c.next();
    const Card c2(b, l2, {10, 10, 10, 10, 10, 10, 10, 10});
    johnson_cook_strength(c2, m);
    const double sigmax = c2.real(5, "SIGMAX", 0), sigsat = c2.real(6, "SIGSAT", 0),
                 epso = c2.real(7, "EPSO", 0);
    if (!(epso > 0))
      c2.fail("EPSO", "the quasi-static threshold strain rate EPSO must be positive (in the "
                      "deck's time unit: 1.0 for 1/s)");
    if (sigmax < 0) c2.fail("SIGMAX", "SIGMAX must not be negative");
    if (sigsat < 0) c2.fail("SIGSAT", "SIGSAT must not be negative");
    m.params["reference_strain_rate"] = epso;
    // LS-DYNA's "no cap" is 1e28 (its default for a blank field).
    if (sigmax > 0 && sigmax < 1e27) m.params["max_hardening_stress"] = sigmax;
    if (sigsat > 0 && sigsat < 1e27) m.params["saturation_stress"] = sigsat;
    failure_strain(c2, 4, "PSFAIL", m);
    add_material(c1, mid, std::move(m));
  }

  // MID, RO, E, PR, SIGY, ETAN, FAIL, TDEL; C, P, LCSS, LCSR, VP; EPS1-EPS8; ES1-ES8
  // (LS-DYNA manual, *MAT_PIECEWISE_LINEAR_PLASTICITY). The yield stress against the
  // effective plastic strain: curve LCSS, else the points (EPS, ES), else SIGY with the
  // tangent ETAN (LS-DYNA's order of precedence).
  void mat_piecewise_linear_plasticity(const Block& b) {
    Cursor c(b);
    skip_title(b, c);
    const Line l = c.next();
    const Card c1(b, l, {10, 10, 10, 10, 10, 10, 10, 10});
    const std::int64_t mid = material_id(c1);
    MaterialCard m = material_card(b, "piecewise_linear_plasticity", l);
    elastic_fields(c1, m.params, 1, 2, 3);
    const double E = m.params["youngs_modulus"];
    const double sigy = c1.real(4, "SIGY", 0), etan = c1.real(5, "ETAN", 0);
    failure_strain(c1, 6, "FAIL", m);
    if (c1.real(7, "TDEL", 0) != 0)
      m.notes.push_back(fmt::format("{}: material {}: TDEL (the time step below which elements "
                                    "are deleted) is ignored",
                                    m.at.str(), mid));
    const Line l2 = c.next();
    const Card c2(b, l2, {10, 10, 10, 10, 10, 10});
    cowper_symonds(c2, 0, "C", 1, "P", m);
    m.lcss = c2.integer(2, "LCSS", 0);
    if (m.lcss < 0) c2.fail("LCSS", "LCSS must be a curve id (> 0) or blank");
    if (m.lcss > 0) m.field_of["hardening_curve"] = where_of(l2).loc("*" + b.name + ".LCSS");
    if (c2.integer(3, "LCSR", 0) != 0)
      c2.fail("LCSR", "a curve of strain-rate scale factors (LCSR) is not supported: give the "
                      "Cowper-Symonds constants C and P");
    rate_form(c2, 4, mid, m);
    if (!c2.blank(5) && c2.real(5, "LCF", 0) != 0)
      c2.fail("LCF", "LCF (a failure curve) is not supported");
    const Line l3 = c.next(), l4 = c.next();
    const Card c3(b, l3, {10, 10, 10, 10, 10, 10, 10, 10}),
        c4(b, l4, {10, 10, 10, 10, 10, 10, 10, 10});
    ParamTable points;
    bool ended = false;
    for (int i = 0; i < 8; ++i) {
      const std::string eps = fmt::format("EPS{}", i + 1), es = fmt::format("ES{}", i + 1);
      const double x = c3.real(i, eps.c_str(), 0), y = c4.real(i, es.c_str(), 0);
      if (i > 0 && x == 0 && y == 0) {
        ended = true;
        continue;
      }
      if (ended)
        c3.fail(eps, fmt::format("{} follows an unused point (EPS and ES both 0): the points "
                                 "must come first, in order",
                                 eps));
      if (i > 0 && !(x > points.x.back()))
        c3.fail(eps, fmt::format("the plastic strains must increase: {} = {} follows {}", eps, x,
                                 points.x.back()));
      points.x.push_back(x);
      points.y.push_back(y);
    }
    const bool tabulated =
        std::any_of(points.y.begin(), points.y.end(), [](double y) { return y != 0; });
    if (m.lcss > 0) {
      if (sigy != 0 || etan != 0 || tabulated)
        m.notes.push_back(fmt::format("{}: material {}: the curve LCSS = {} gives the yield "
                                      "stress; SIGY, ETAN and EPS/ES are not used",
                                      m.at.str(), mid, m.lcss));
    } else if (tabulated) {
      if (sigy != 0 || etan != 0)
        m.notes.push_back(fmt::format("{}: material {}: the points EPS/ES give the yield stress; "
                                      "SIGY and ETAN are not used",
                                      m.at.str(), mid));
      m.tables["hardening_curve"] = std::move(points);
      m.field_of["hardening_curve"] = where_of(l4).loc("*" + b.name + ".ES1");
      m.field_of["hardening_curve[]"] = where_of(l4).loc("*" + b.name + ".ES");
    } else {
      if (std::any_of(points.x.begin(), points.x.end(), [](double x) { return x != 0; }))
        m.notes.push_back(fmt::format("{}: material {}: EPS gives plastic strains but every ES "
                                      "is blank: the points are not used, SIGY and ETAN give "
                                      "the yield stress",
                                      m.at.str(), mid));
      bilinear_hardening(c1, E, " (or give LCSS, or EPS and ES)", m);
    }
    add_material(c1, mid, std::move(m));
  }

  void mat_johnson_cook(const Block& b) {
    Cursor c(b);
    skip_title(b, c);
    const Line l = c.next();
    const Card c1(b, l, {10, 10, 10, 10, 10, 10, 10, 10});
    const std::int64_t mid = material_id(c1);
    MaterialCard m = material_card(b, "johnson_cook", l);
    const double ro = c1.real(1, "RO"), G = c1.real(2, "G"), E = c1.real(3, "E"),
                 pr = c1.real(4, "PR");
    if (!(ro > 0)) c1.fail("RO", "the density RO must be positive");
    if (!(G > 0)) c1.fail("G", "the shear modulus G must be positive");
    if (E < 0) c1.fail("E", "E must not be negative");
    m.params["density"] = ro;
    // anvil's model is hypoelastic with E and nu. LS-DYNA takes G for solids and the
    // pressure from an EOS; with no EOS model here, the bulk modulus comes from PR (or E),
    // else from the EOS's sound speed (resolved when the part's EOS is known).
    if (pr != 0) {
      if (!(pr > -1 && pr < 0.5))
        c1.fail("PR", fmt::format("Poisson's ratio PR = {} must be in (-1, 0.5)", pr));
      m.params["youngs_modulus"] = 2 * G * (1 + pr);
      m.params["poissons_ratio"] = pr;
    } else if (E > 0) {
      const double nu = E / (2 * G) - 1;
      if (!(nu > -1 && nu < 0.5))
        c1.fail("E", fmt::format("E = {} and G = {} give Poisson's ratio {}, outside (-1, 0.5)", E,
                                 G, nu));
      m.params["youngs_modulus"] = E;
      m.params["poissons_ratio"] = nu;
    } else {
      m.params["shear_modulus_only"] = G; // needs the EOS; completed per part in config()
    }
    if (c1.real(6, "VP") != 0)
      m.notes.push_back(fmt::format("{}: material {}: VP = 1 (viscoplastic rate form) is "
                                    "replaced by anvil's scaled yield stress (VP = 0)",
                                    m.at.str(), mid));
    if (c1.real(7, "RATEOP") != 0)
      m.notes.push_back(fmt::format("{}: material {}: RATEOP is ignored; anvil uses the "
                                    "original form 1 + C ln(rate / EPSO)",
                                    m.at.str(), mid));
    const Line l2 = c.next();
    const Card c2(b, l2, {10, 10, 10, 10, 10, 10, 10, 10});
    johnson_cook_strength(c2, m);
    const double M = c2.real(4, "M"), TM = c2.real(5, "TM"), TR = c2.real(6, "TR"),
                 EPSO = c2.real(7, "EPSO");
    if (!(M > 0))
      c2.fail("M", "the thermal softening exponent M must be positive (anvil's johnson_cook "
                   "always softens; give M and TM)");
    if (!(TR > 0)) c2.fail("TR", "the room temperature TR must be positive (kelvin)");
    if (!(TM > TR)) c2.fail("TM", "the melt temperature TM must exceed the room temperature TR");
    if (!(EPSO > 0)) c2.fail("EPSO", "the reference strain rate EPSO must be positive");
    m.params["m"] = M;
    m.params["melt_temperature"] = TM;
    m.params["room_temperature"] = TR;
    m.params["reference_strain_rate"] = EPSO;
    const Line l3 = c.next();
    const Card c3(b, l3, {10, 10, 10, 10, 10, 10, 10, 10});
    const double cp = c3.real(0, "CP");
    if (!(cp > 0)) c3.fail("CP", "the specific heat CP must be positive");
    m.params["specific_heat"] = cp;
    bool failure = c3.real(1, "PC") != 0 || c3.real(4, "D1") != 0 || c3.real(5, "D2") != 0 ||
                   c3.real(6, "D3") != 0 || c3.real(7, "D4") != 0;
    const Line l4 = c.next();
    const Card c4(b, l4, {10, 10, 10, 10, 10});
    failure = failure || c4.real(0, "D5") != 0 || c4.real(2, "EROD") != 0;
    if (failure)
      m.notes.push_back(fmt::format("{}: material {}: spall (PC, SPALL) and damage (D1-D5, "
                                    "EROD) are ignored: anvil's johnson_cook has no damage, so "
                                    "these elements are never deleted (anvil erodes at a plastic "
                                    "strain: the FAIL of *MAT_024 or a YAML deck's part key "
                                    "`erosion: {{plastic_strain: ...}}`)",
                                    m.at.str(), mid));
    add_material(c1, mid, std::move(m));
  }

  void other_material(const Block& b) {
    Cursor c(b);
    skip_title(b, c);
    if (!c.done()) {
      const Line l = c.next();
      const Card card(b, l, {10}, Card::Extra::keep);
      std::int64_t mid = 0;
      try {
        mid = card.integer(0, "MID", 0);
      } catch (const InputError&) {
        mid = 0;
      }
      if (mid > 0) materials_.emplace(mid, material_card(b, "", l));
    }
    c.skip_rest(); // the keyword is listed as ignored, whatever its cards
    unsupported(b);
  }

  void eos(const Block& b) {
    Cursor c(b);
    skip_title(b, c);
    const Line l = c.next();
    const Card card(b, l, {10, 10, 10, 10, 10, 10, 10, 10});
    const std::int64_t id = card.integer(0, "EOSID", 0);
    if (id <= 0) card.fail("EOSID", fmt::format("EOSID must be a positive id, found {}", id));
    EosCard e;
    e.keyword = b.name;
    e.at = e.at2 = where_of(l);
    if (starts_with(b.name, "EOS_GRUNEISEN")) {
      e.c = card.real(1, "C");
      e.s1 = card.real(2, "S1");
      e.s2 = card.real(3, "S2");
      e.s3 = card.real(4, "S3");
      e.gamma0 = card.real(5, "GAMAO");
      e.a = card.real(6, "A");
      e.e0 = card.real(7, "E0");
      // Card 2: V0, (unused), LCID.
      const Line l2 = c.next();
      const Card card2(b, l2, {10, 10, 10});
      e.at2 = where_of(l2);
      e.v0 = card2.real(0, "V0");
      e.lcid = card2.id(2, "LCID");
    } else {
      c.skip_rest(); // other forms' cards vary; anvil models none of them
    }
    const auto [it, fresh] = eos_.emplace(id, std::move(e));
    if (!fresh)
      card.fail("EOSID", fmt::format("equation of state {} is defined twice (first at {})", id,
                                     it->second.at.str()));
  }

  void hourglass(const Block& b) {
    Cursor c(b);
    while (!c.done()) {
      skip_title(b, c);
      const Line l = c.next();
      const Card card(b, l, {10, 10, 10, 10, 10, 10, 10, 10});
      const std::int64_t id = card.integer(0, "HGID", 0);
      if (id <= 0) card.fail("HGID", fmt::format("HGID must be a positive id, found {}", id));
      HourglassCard h{card.integer(1, "IHQ", 0), card.real(2, "QM"), card.real(4, "Q1"),
                      card.real(5, "Q2"), where_of(l)};
      check_hourglass(card, h.ihq, "IHQ", h.qm, "QM");
      if (h.q1 < 0) card.fail("Q1", "Q1 must not be negative");
      if (h.q2 < 0) card.fail("Q2", "Q2 must not be negative");
      const auto [it, fresh] = hourglass_.emplace(id, h);
      if (!fresh)
        card.fail("HGID", fmt::format("hourglass {} is defined twice (first at {})", id,
                                      it->second.at.str()));
    }
  }

  static void check_hourglass(const Card& card, std::int64_t ihq, const char* ihq_name, double qm,
                              const char* qm_name) {
    if (ihq < 0 || ihq > 10)
      card.fail(ihq_name, fmt::format("{} = {} is not an LS-DYNA hourglass type", ihq_name, ihq));
    if (!(qm >= 0 && qm <= 1)) card.fail(qm_name, fmt::format("{} must be in [0, 1]", qm_name));
  }

  // ---- loads, constraints, contact ------------------------------------------------------

  // The deck's name of node set `sid` (an error at `at`, naming `key`, when undefined).
  std::string node_set_name(std::int64_t sid, const Where& at, const std::string& key) const {
    if (!node_sets_.count(sid))
      throw InputError(at.loc(key),
                       fmt::format("node set {} is not defined (*SET_NODE_LIST)", sid));
    return fmt::format("nodeset_{}", sid);
  }

  // The constraints, prescribed motions and body loads of the deck into `c` (part of
  // config()): `mesh` gains the sets of the single-node groups; `warnings` what anvil does
  // otherwise than LS-DYNA might.
  void conditions(Config& c, Mesh& mesh, std::vector<std::string>& warnings) {
    // Constraints and prescribed motions become conditions in card order, so that a later
    // card wins on the node components two hold, as in the YAML deck: one condition per card
    // by set; single nodes (*BOUNDARY_SPC_NODE, *NODE TC, *BOUNDARY_PRESCRIBED_MOTION_NODE)
    // grouped by what they hold, one set each at its first card's place, so that a deck with
    // thousands of them makes a few conditions, not thousands. A card joins its group only
    // if no card since the group's first holds the same node component; else it starts a
    // new group at its own place (QA round 23: a *NODE TC joined a group before a motion
    // card on its node, and the motion won).

    auto warn_if_curve_ends = [&](std::int64_t lcid, const CurveCard& cc) {
      curve_ends_early(lcid, cc, warnings);
    };
    std::vector<std::pair<std::int64_t, BoundaryCondition>> ordered; // (card seq, condition)
    auto fix_condition = [&](std::int64_t seq, const std::string& set_name,
                             const SourceLocation& where, std::array<bool, 3> fix) {
      BoundaryCondition bc;
      bc.nodes.name = set_name;
      bc.nodes.where = where;
      bc.fix = fix;
      bc.where = where;
      ordered.emplace_back(seq, std::move(bc));
    };
    // *BOUNDARY_PRESCRIBED_MOTION_RIGID: the body of a rigid part.
    // A prescribed motion on the nodes of `set_name`, or (*BOUNDARY_PRESCRIBED_MOTION_RIGID,
    // m.pid) on the body of a rigid part.
    auto motion_condition = [&](const MotionCard& m, std::int64_t seq,
                                const std::string& set_name) {
      const std::string key = "*" + m.keyword;
      const CurveCard& cc = curve(m.lcid, m.at.loc(key + ".LCID"));
      const TimeCurve& tc = cc.curve;
      if (const auto problem = time_history_problem(m.sf, tc, m.displacement); !problem.empty())
        throw InputError(m.at.loc(key + ".LCID"), fmt::format("curve {}: {}", m.lcid, problem));
      warn_if_curve_ends(m.lcid, cc);
      warn_if_zero_scale(m.sf, m.at, key, warnings);
      BoundaryCondition bc;
      if (m.pid != 0)
        bc.nodes.part = rigid_part(m.pid, m.at.loc(key + ".PID"),
                                   key + " drives a rigid body (give "
                                         "*BOUNDARY_PRESCRIBED_MOTION_SET for nodes)");
      else
        bc.nodes.name = set_name;
      bc.nodes.where = m.at.loc(key);
      bc.prescribed = true;
      bc.motion = m.displacement ? BoundaryCondition::Motion::displacement
                                 : BoundaryCondition::Motion::velocity;
      if (m.rotation) {
        bc.spin_components[static_cast<std::size_t>(m.dof)] = true;
        bc.spin[m.dof] = m.sf;
        bc.rotations = true;
      } else {
        bc.components[static_cast<std::size_t>(m.dof)] = true;
        bc.value[m.dof] = m.sf;
      }
      bc.curve = tc;
      bc.birth = m.birth;
      bc.death = m.death;
      bc.where = bc.nodes.where;
      ordered.emplace_back(seq, std::move(bc));
    };

    // Every card in deck order: (seq, kind, index) with kind 0 an SPC, 1 a *NODE TC, 2 a
    // motion.
    std::vector<std::tuple<std::int64_t, int, std::size_t>> cards;
    for (std::size_t k = 0; k < spcs_.size(); ++k) cards.emplace_back(spcs_[k].seq, 0, k);
    for (std::size_t k = 0; k < node_tc_.size(); ++k) cards.emplace_back(node_tc_[k].seq, 1, k);
    for (std::size_t k = 0; k < motions_.size(); ++k) cards.emplace_back(motions_[k].seq, 2, k);
    std::sort(cards.begin(), cards.end());
    // The place (seq) of the condition that last held each node component, and the groups
    // of single nodes: key (fix mask, or motion DOF, VAD, LCID, SF) -> its latest group.
    std::vector<std::array<std::int64_t, 3>> held(mesh.nodes.size(), {-1, -1, -1});
    auto hold = [&](std::int64_t pos, std::array<bool, 3> on, std::int64_t seq) {
      for (std::size_t i = 0; i < 3; ++i)
        if (on[i]) held[static_cast<std::size_t>(pos)][i] = seq;
    };
    struct Group {
      std::int64_t seq;
      std::vector<std::int64_t> ids;
      std::array<bool, 3> on;
      Where at;
      std::string keyword;      // of its first card
      const MotionCard* motion; // its first card, for a motion group
    };
    std::vector<Group> groups;
    using GroupKey = std::tuple<int, int, bool, std::int64_t, double, double, double>;
    std::map<GroupKey, std::size_t> latest;
    auto add_single = [&](const GroupKey& key, std::int64_t pos, std::array<bool, 3> on,
                          std::int64_t seq, const Where& at, const std::string& keyword,
                          const MotionCard* motion) {
      const auto it = latest.find(key);
      bool join = it != latest.end();
      if (join)
        for (std::size_t i = 0; i < 3; ++i)
          if (on[i] && held[static_cast<std::size_t>(pos)][i] > groups[it->second].seq)
            join = false;
      if (!join) {
        latest[key] = groups.size();
        groups.push_back({seq, {}, on, at, keyword, motion});
      }
      Group& g = groups[latest[key]];
      g.ids.push_back(pos);
      hold(pos, on, g.seq);
    };
    for (const auto& [seq, kind, k] : cards) {
      if (kind == 0) {
        const Spc& sp = spcs_[k];
        if (!sp.fix[0] && !sp.fix[1] && !sp.fix[2]) continue; // rotations only
        const int mask = (sp.fix[0] ? 1 : 0) | (sp.fix[1] ? 2 : 0) | (sp.fix[2] ? 4 : 0);
        if (sp.set != 0) {
          const std::string name = node_set_name(sp.set, sp.at, "*" + sp.keyword + ".NSID");
          fix_condition(seq, name, sp.at.loc("*" + sp.keyword), sp.fix);
          for (const auto pos : mesh.node_sets.at(name)) hold(pos, sp.fix, seq);
        } else {
          const auto pos =
              node_position(sp.node, sp.at, "*" + sp.keyword + ".NID", "the constraint");
          add_single({0, mask, false, 0, 0.0, 0.0, 0.0}, pos, sp.fix, seq, sp.at, sp.keyword,
                     nullptr);
        }
      } else if (kind == 1) {
        // TC: 1 x, 2 y, 3 z, 4 x and y, 5 y and z, 6 z and x, 7 all.
        static constexpr int masks[8] = {0, 1, 2, 4, 3, 6, 5, 7};
        const NodeTc& t = node_tc_[k];
        const int mask = masks[t.tc];
        add_single({0, mask, false, 0, 0.0, 0.0, 0.0}, node_index_.at(t.nid),
                   {(mask & 1) != 0, (mask & 2) != 0, (mask & 4) != 0}, seq, t.at, "NODE", nullptr);
      } else {
        const MotionCard& m = motions_[k];
        std::array<bool, 3> on{false, false, false};
        on[static_cast<std::size_t>(m.dof)] = true;
        if (m.pid != 0) {
          motion_condition(m, seq, "");
        } else if (m.set != 0) {
          const std::string name = node_set_name(m.set, m.at, "*" + m.keyword + ".NSID");
          motion_condition(m, seq, name);
          for (const auto pos : mesh.node_sets.at(name)) hold(pos, on, seq);
        } else {
          const auto pos = node_position(m.node, m.at, "*" + m.keyword + ".NID", "the motion");
          add_single({1, m.dof, m.displacement, m.lcid, m.sf, m.birth, m.death}, pos, on, seq, m.at,
                     m.keyword, &m);
        }
      }
    }
    // The groups' sets, named in deck order: spc_x, spc_x_2, ...; motion_nodes_1, ...
    std::map<std::string, int> named;
    int motion_groups = 0;
    for (Group& g : groups) {
      std::sort(g.ids.begin(), g.ids.end());
      g.ids.erase(std::unique(g.ids.begin(), g.ids.end()), g.ids.end());
      std::string name;
      if (g.motion) {
        name = fmt::format("motion_nodes_{}", ++motion_groups);
      } else {
        name =
            fmt::format("spc_{}{}{}", g.on[0] ? "x" : "", g.on[1] ? "y" : "", g.on[2] ? "z" : "");
        if (const int n = ++named[name]; n > 1) name += fmt::format("_{}", n);
      }
      mesh.node_sets[name] = g.ids;
      if (g.motion)
        motion_condition(*g.motion, g.seq, name);
      else
        fix_condition(g.seq, name, g.at.loc(g.keyword == "NODE" ? "*NODE.TC" : "*" + g.keyword),
                      g.on);
    }
    // *MAT_RIGID CMO = 1: its bodies' held translations and rotations, before every card
    // (a prescribed motion on a held component wins, as a later card does).
    static constexpr int masks[8] = {0, 1, 2, 4, 3, 6, 5, 7};
    for (const auto& [part, con] : rigid_constraints_) {
      BoundaryCondition bc;
      bc.nodes.part = part;
      bc.nodes.where = con.at.loc("*MAT_RIGID.CMO");
      bc.where = bc.nodes.where;
      for (std::size_t i = 0; i < 3; ++i) {
        bc.fix[i] = (masks[con.con1] >> i & 1) != 0;
        bc.fix_spin[i] = (masks[con.con2] >> i & 1) != 0;
      }
      bc.rotations = con.con2 != 0;
      ordered.emplace_back(-1, std::move(bc));
    }
    std::stable_sort(ordered.begin(), ordered.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    for (auto& [seq, bc] : ordered) c.boundary_conditions.push_back(std::move(bc));
    warn_of_held_twice(c, mesh, warnings);

    // Body loads: LS-DYNA's are base accelerations, so the body is pushed the other way: a
    // positive *LOAD_BODY_Z of 9.81 is gravity along -z.
    for (const auto& bl : bodies_) {
      const std::string key = "*" + bl.keyword;
      const CurveCard& cc = curve(bl.lcid, bl.at.loc(key + ".LCID"));
      if (const auto problem = time_history_problem(bl.sf, cc.curve, false); !problem.empty())
        throw InputError(bl.at.loc(key + ".LCID"), fmt::format("curve {}: {}", bl.lcid, problem));
      warn_if_curve_ends(bl.lcid, cc);
      warn_if_zero_scale(bl.sf, bl.at, key, warnings);
      BodyLoad load;
      load.acceleration[bl.axis] = -bl.sf;
      load.curve = cc.curve;
      load.where = bl.at.loc(key);
      c.body_loads.push_back(load);
    }
  }

  // A curve that ends before ENDTIM while still changing: said once per curve.
  void curve_ends_early(std::int64_t lcid, const CurveCard& cc,
                        std::vector<std::string>& warnings) {
    const TimeCurve& tc = cc.curve;
    const std::size_t last = tc.t.size() - 1;
    if (endtim_ > tc.t[last] && last > 0 && tc.value[last] != tc.value[last - 1] &&
        curves_warned_.insert(lcid).second)
      warnings.push_back(fmt::format(
          "{}: curve {} ends at t = {} before the end time {}: anvil holds its last value "
          "there, where LS-DYNA would extrapolate its last slope (extend the curve to the end "
          "time to have the same run in both)",
          cc.at.str(), lcid, tc.t[last], endtim_));
  }

  // SF = 0 written out: the motion or load is zero (a blank SF is 1). LS-DYNA may read such
  // a 0 as the default 1 (QA round 24), so it is said.
  static void warn_if_zero_scale(double sf, const Where& at, const std::string& key,
                                 std::vector<std::string>& warnings) {
    if (sf == 0)
      warnings.push_back(fmt::format("{}: {}.SF is 0: anvil applies zero times the curve (a "
                                     "blank SF is 1; give the scale you mean)",
                                     at.str(), key));
  }

  // Curve `lcid` of a load card, as the time history of SF times it (an error where it
  // cannot be one, a warning where it ends early).
  const TimeCurve& load_curve(std::int64_t lcid, double sf, const Where& at, const std::string& key,
                              std::vector<std::string>& warnings) {
    const CurveCard& cc = curve(lcid, at.loc(key + ".LCID"));
    if (const auto problem = time_history_problem(sf, cc.curve, false); !problem.empty())
      throw InputError(at.loc(key + ".LCID"), fmt::format("curve {}: {}", lcid, problem));
    curve_ends_early(lcid, cc, warnings);
    warn_if_zero_scale(sf, at, key, warnings);
    return cc.curve;
  }

  // The external loads of the deck into `c` (part of config()): forces on nodes (sets)
  // and pressures on segments. `mesh` gains the sets they need: the nodes of the single-node
  // cards, grouped by what they apply (load_nodes_N), and the faces of the segments, as side
  // sets of the elements' faces: SEGSET (segset_SID, or load_segments_N for single-segment
  // cards grouped by curve and scale) for the segments ordered as the face is seen from
  // outside its element, SEGSET_reversed for the others. LS-DYNA's positive pressure acts
  // against the segment's right-hand normal (N1-N2-N3-N4), anvil's against the face's
  // outward one: the reversed faces take -SF.
  void loads(Config& c, Mesh& mesh, std::vector<std::string>& warnings) {
    // Forces: a set's card is a load; single nodes are grouped by (DOF, LCID, SF), a node's
    // second card of the same kind into a second group, and so on (LS-DYNA adds repeated
    // loads; a set holds a node once, QA round 25).
    std::map<std::tuple<int, std::int64_t, double>, std::vector<std::size_t>> node_groups;
    int node_group_count = 0;
    for (const auto& nl : node_loads_) {
      const std::string key = "*" + nl.keyword;
      Load load;
      load.kind = Load::Kind::force;
      load.force[nl.dof] = nl.sf;
      load.curve = load_curve(nl.lcid, nl.sf, nl.at, key, warnings);
      load.where = nl.at.loc(key);
      load.target.where = nl.at.loc(key + (nl.set != 0 ? ".NSID" : ".NID"));
      if (nl.set != 0) {
        load.target.name = node_set_name(nl.set, nl.at, key + ".NSID");
        c.loads.push_back(load);
        continue;
      }
      const auto pos = node_position(nl.node, nl.at, key + ".NID", "the load");
      auto& layers = node_groups[std::tuple{nl.dof, nl.lcid, nl.sf}];
      std::vector<std::int64_t>* ids = nullptr;
      for (const std::size_t l : layers) {
        auto& set = mesh.node_sets[c.loads[l].target.name];
        if (!std::binary_search(set.begin(), set.end(), pos)) {
          ids = &set;
          break;
        }
      }
      if (!ids) {
        load.target.name = fmt::format("load_nodes_{}", ++node_group_count);
        layers.push_back(c.loads.size());
        c.loads.push_back(load);
        ids = &mesh.node_sets[load.target.name];
      }
      ids->insert(std::lower_bound(ids->begin(), ids->end(), pos), pos);
    }
    if (segment_loads_.empty()) return;

    // Every face of every element, by its face_key, for the segments' lookup.
    struct Face {
      FaceKey sorted;
      std::int64_t element;
      int face;
    };
    std::vector<Face> faces;
    std::int64_t gid = 0;
    for (const auto& blk : mesh.blocks)
      for (const auto& h : blk.elements) {
        for (int f = 0; f < 6; ++f)
          if (const FaceKey k = face_key(h, f); is_face(k)) faces.push_back({k, gid, f});
        ++gid;
      }
    std::sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) {
      return std::tie(a.sorted, a.element, a.face) < std::tie(b.sorted, b.element, b.face);
    });
    const auto offsets = mesh.block_offsets();
    // The face a segment is (of the lowest element that has it), and whether the segment
    // runs the other way round. A triangle is N1 N2 N3 N3 (LS-DYNA's triangular segment),
    // a triangular face of a wedge, pyramid or tetrahedron.
    auto face_of = [&](const std::array<std::int64_t, 4>& ids, const Where& at,
                       const std::string& key) -> std::pair<SideEntry, bool> {
      std::array<std::int64_t, 4> pos{};
      for (int a = 0; a < 4; ++a)
        pos[a] = node_position(ids[a], at, fmt::format("{}.N{}", key, a + 1), "the segment");
      const FaceKey sorted = face_key(pos);
      const std::array<std::int64_t, 4> seg = face_nodes(pos);
      if (!is_face(sorted) || (sorted[0] < 0 && seg[2] != seg[3]))
        throw InputError(at.loc(key + ".N4"),
                         fmt::format("segment ({}, {}, {}, {}) repeats a node other than as a "
                                     "triangle (N1 N2 N3 N3, or one node twice in neighbouring "
                                     "places)",
                                     ids[0], ids[1], ids[2], ids[3]));
      const auto it =
          std::lower_bound(faces.begin(), faces.end(), sorted,
                           [](const Face& f, const FaceKey& k) { return f.sorted < k; });
      if (it == faces.end() || it->sorted != sorted)
        throw InputError(at.loc(key + ".N1"),
                         fmt::format("segment ({}, {}, {}, {}) is not a face of a solid "
                                     "element of the model",
                                     ids[0], ids[1], ids[2], ids[3]));
      const auto b = static_cast<std::size_t>(
          std::upper_bound(offsets.begin(), offsets.end(), it->element) - offsets.begin() - 1);
      const Hex& h = mesh.blocks[b].elements[static_cast<std::size_t>(it->element - offsets[b])];
      // Both go round their corners (3 or 4) the same way, or the other way round.
      const std::array<std::int64_t, 4> face = face_nodes(h, it->face);
      const int n = sorted[0] < 0 ? 3 : 4;
      const auto k = std::find(face.begin(), face.begin() + n, seg[0]) - face.begin();
      const bool same = face[(k + 1) % n] == seg[1] && face[(k + 2) % n] == seg[2];
      const bool reversed = face[(k + n - 1) % n] == seg[1] && face[(k + n - 2) % n] == seg[2];
      if (!same && !reversed)
        throw InputError(at.loc(key + ".N1"),
                         fmt::format("segment ({}, {}, {}, {}) does not go round its face in "
                                     "order (its nodes cross over)",
                                     ids[0], ids[1], ids[2], ids[3]));
      return {SideEntry{it->element, it->face}, reversed};
    };
    // A pressure on the faces of `segments` (with their cards), as up to two loads on side
    // sets `name` and `name`_reversed.
    auto add_pressure = [&](const std::string& name,
                            const std::vector<std::array<std::int64_t, 4>>& segments,
                            const std::vector<Where>& at, const std::string& key,
                            const SegmentLoadCard& card, const TimeCurve& curve) {
      // Per orientation, layers: a face's k-th segment goes into layer k (a segment listed
      // twice is pressed twice, as LS-DYNA does; a side set holds a face once).
      std::vector<std::vector<SideEntry>> side[2];
      std::map<std::pair<std::int64_t, int>, std::size_t> seen[2];
      for (std::size_t k = 0; k < segments.size(); ++k) {
        const auto [entry, reversed] = face_of(segments[k], at[k], key);
        const std::size_t layer = seen[reversed][{entry.element, entry.face}]++;
        if (side[reversed].size() <= layer) side[reversed].resize(layer + 1);
        side[reversed][layer].push_back(entry);
      }
      for (int r = 0; r < 2; ++r)
        for (std::size_t layer = 0; layer < side[r].size(); ++layer) {
          const std::string set = (r ? name + "_reversed" : name) +
                                  (layer > 0 ? fmt::format("_{}", layer + 1) : std::string());
          if (!mesh.side_sets.count(set)) mesh.side_sets[set] = side[r][layer];
          Load load;
          load.kind = Load::Kind::pressure;
          load.pressure = r ? -card.sf : card.sf;
          load.curve = curve;
          load.birth = card.arrival;
          load.death = card.death;
          load.where = card.at.loc("*" + card.keyword);
          load.target.name = set;
          load.target.where = load.where;
          c.loads.push_back(load);
        }
    };
    // Single segments grouped by (LCID, SF, AT), each group at its first card's place.
    std::map<std::tuple<std::int64_t, double, double>, std::size_t> groups;
    struct Group {
      const SegmentLoadCard* first;
      std::vector<std::array<std::int64_t, 4>> segments;
      std::vector<Where> at;
    };
    std::vector<Group> group;
    for (const auto& sl : segment_loads_) {
      const std::string key = "*" + sl.keyword;
      const TimeCurve& curve = load_curve(sl.lcid, sl.sf, sl.at, key, warnings);
      if (sl.set != 0) {
        const auto it = segment_sets_.find(sl.set);
        if (it == segment_sets_.end())
          throw InputError(sl.at.loc(key + ".SSID"),
                           fmt::format("segment set {} is not defined (*SET_SEGMENT)", sl.set));
        add_pressure(fmt::format("segset_{}", sl.set), it->second.segments, it->second.at,
                     "*SET_SEGMENT", sl, curve);
        continue;
      }
      const auto [it, fresh] = groups.emplace(std::tuple{sl.lcid, sl.sf, sl.arrival}, group.size());
      if (fresh) group.push_back({&sl, {}, {}});
      group[it->second].segments.push_back(sl.nodes);
      group[it->second].at.push_back(sl.at);
    }
    for (std::size_t g = 0; g < group.size(); ++g) {
      const SegmentLoadCard& first = *group[g].first;
      add_pressure(fmt::format("load_segments_{}", g + 1), group[g].segments, group[g].at,
                   "*" + first.keyword, first, curves_.at(first.lcid).curve);
    }
  }

  void spc(const Block& b, bool set) {
    Cursor c(b);
    // The _ID option adds one card (ID, HEADING) to the keyword, not one per constraint:
    // any number of NID/NSID cards follow it (LS-DYNA manual, *BOUNDARY_SPC).
    if (ends_with(b.name, "_ID")) c.next();
    while (!c.done()) {
      const Line l = c.next();
      const Card card(b, l, {10, 10, 10, 10, 10, 10, 10, 10});
      const char* what = set ? "NSID" : "NID";
      Spc s;
      (set ? s.set : s.node) = card.integer(0, what, 0);
      if ((set ? s.set : s.node) <= 0)
        card.fail(what, fmt::format("{} must be a positive id", what));
      if (card.integer(1, "CID", 0) != 0)
        card.fail("CID", "constraints in a local coordinate system (CID) are not supported");
      static constexpr const char* dofs[6] = {"DOFX", "DOFY", "DOFZ", "DOFRX", "DOFRY", "DOFRZ"};
      for (int i = 0; i < 6; ++i) {
        const auto v = card.integer(2 + i, dofs[i], 0);
        if (v != 0 && v != 1) card.fail(dofs[i], fmt::format("{} must be 0 or 1", dofs[i]));
        // Rotations: a solid's nodes have none (LS-DYNA ignores them there too).
        if (i < 3) s.fix[i] = v == 1;
      }
      s.at = where_of(l);
      s.keyword = b.name;
      s.seq = card_seq_++;
      spcs_.push_back(s);
    }
  }

  // LCID, SF, LCIDDR, XC, YC, ZC, CID (LS-DYNA manual, *LOAD_BODY). LCIDDR (the curve of
  // a dynamic relaxation) is left out with a warning: anvil has no such phase.
  void body_load(const Block& b) {
    Cursor c(b);
    const Line l = c.next();
    const Card card(b, l, {10, 10, 10, 10, 10, 10, 10});
    BodyCard bc;
    bc.axis = b.name.back() - 'X';
    bc.lcid = card.integer(0, "LCID", 0);
    if (bc.lcid <= 0) card.fail("LCID", "LCID must be the id of a *DEFINE_CURVE");
    bc.sf = card.real(1, "SF", 1.0);
    if (card.integer(6, "CID", 0) != 0)
      card.fail("CID", "body loads in a local coordinate system (CID) are not supported");
    if (card.integer(2, "LCIDDR", 0) != 0)
      warnings_.push_back(fmt::format("{}: *{}: LCIDDR (a dynamic relaxation curve) is "
                                      "ignored: anvil has no dynamic relaxation phase, the run "
                                      "starts unloaded and LCID loads it",
                                      where_of(l).str(), b.name));
    bc.at = where_of(l);
    bc.keyword = b.name;
    bodies_.push_back(bc);
  }

  // Field 1 of a card on a node (NID) or a node set (NSID): a positive id.
  static std::int64_t node_or_set_id(const Card& card, bool set) {
    const char* what = set ? "NSID" : "NID";
    const std::int64_t id = card.integer(0, what, 0);
    if (id <= 0) card.fail(what, fmt::format("{} must be a positive id", what));
    return id;
  }

  // Field 2, DOF: a translation, 1, 2 or 3 (x, y, z), returned as 0, 1, 2; `anvil_does`
  // ends the message for any other ("anvil ...").
  static int translation_dof(const Card& card, const char* anvil_does) {
    const auto dof = card.integer(1, "DOF", 0);
    if (dof < 1 || dof > 3)
      card.fail("DOF", fmt::format("DOF = {} is not supported: anvil {}", dof, anvil_does));
    return static_cast<int>(dof - 1);
  }

  // Any number of cards NID (NSID), DOF, LCID, SF, CID, M1, M2, M3 (LS-DYNA manual,
  // *LOAD_NODE). anvil applies forces along x, y, z (DOF 1-3) in the global system; a
  // follower force, a moment or a local system would be another load, so it is an error.
  void node_load(const Block& b, bool set) {
    Cursor c(b);
    while (auto l = c.next_record()) {
      const Card card(b, *l, {10, 10, 10, 10, 10, 10, 10, 10});
      NodeLoadCard nl;
      (set ? nl.set : nl.node) = node_or_set_id(card, set);
      nl.dof = translation_dof(card, "applies forces along x, y, z (DOF 1, 2, 3); solid nodes "
                                     "take no moments");
      nl.lcid = card.integer(2, "LCID", 0);
      if (nl.lcid <= 0) card.fail("LCID", "LCID must be the id of a *DEFINE_CURVE");
      nl.sf = card.real(3, "SF", 1.0);
      if (card.integer(4, "CID", 0) != 0)
        card.fail("CID", "forces in a local coordinate system (CID) are not supported");
      nl.at = where_of(*l);
      nl.keyword = b.name;
      node_loads_.push_back(nl);
    }
  }

  // *LOAD_SEGMENT: any number of cards LCID, SF, AT, N1, N2, N3, N4 (N5: a higher-order
  // segment's, not supported); *LOAD_SEGMENT_SET: any number of cards SSID, LCID, SF, AT.
  // The _ID option adds one card (ID, HEADING) first. AT (the arrival time): the pressure
  // acts from then on, SF times the curve's value at the time (the curve is not shifted).
  void segment_load(const Block& b, bool set) {
    Cursor c(b);
    if (ends_with(b.name, "_ID")) c.next();
    while (auto l = c.next_record()) {
      const Card card(b, *l, {10, 10, 10, 10, 10, 10, 10, 10});
      SegmentLoadCard sl;
      const int base = set ? 1 : 0; // LCID's field
      if (set) {
        sl.set = card.integer(0, "SSID", 0);
        if (sl.set <= 0) card.fail("SSID", "SSID must be a positive id");
      }
      sl.lcid = card.integer(base, "LCID", 0);
      if (sl.lcid <= 0) card.fail("LCID", "LCID must be the id of a *DEFINE_CURVE");
      sl.sf = card.real(base + 1, "SF", 1.0);
      sl.arrival = card.real(base + 2, "AT", 0);
      if (sl.arrival < 0) card.fail("AT", fmt::format("AT = {} is negative", sl.arrival));
      if (set) {
        // DT (a death time, in recent LS-DYNA versions; 0 or blank: never), then nothing.
        const double dt = card.real(4, "DT", 0);
        if (dt != 0 && dt < 1e20) sl.death = dt;
        if (!(sl.death > sl.arrival))
          card.fail("DT", fmt::format("DT = {} is not after AT = {}", dt, sl.arrival));
        for (int k = 5; k < card.size(); ++k)
          if (!card.blank(k))
            card.fail(fmt::format("field {}", k + 1),
                      "a *LOAD_SEGMENT_SET card holds SSID, LCID, SF, AT and DT");
      }
      if (!set) {
        for (int a = 0; a < 4; ++a) {
          const std::string name = fmt::format("N{}", a + 1);
          sl.nodes[a] = card.integer(3 + a, name, 0);
          if (sl.nodes[a] <= 0) card.fail(name, segment_node_needed(name));
        }
        if (card.integer(7, "N5", 0) != 0)
          card.fail("N5", "higher-order segments (N5-N8) are not supported: anvil's faces are "
                          "the quadrilaterals of 8-node hexahedra");
      }
      sl.at = where_of(*l);
      sl.keyword = b.name;
      segment_loads_.push_back(sl);
    }
  }

  // *SET_SEGMENT(_TITLE): SID, DA1-DA4, SOLVER; then any number of cards N1, N2, N3, N4,
  // A1-A4 (the attributes are not used).
  void segment_set(const Block& b) {
    Cursor c(b);
    skip_title(b, c);
    const Line l = c.next();
    const Card head(b, l, {10, 10, 10, 10, 10, 10});
    const std::int64_t sid = head.integer(0, "SID", 0);
    if (sid <= 0) head.fail("SID", fmt::format("SID must be a positive set id, found {}", sid));
    SegmentSet s;
    s.head = where_of(l);
    while (auto r = c.next_record()) {
      const Card card(b, *r, {10, 10, 10, 10, 10, 10, 10, 10});
      std::array<std::int64_t, 4> n{};
      for (int a = 0; a < 4; ++a) {
        const std::string name = fmt::format("N{}", a + 1);
        n[a] = card.integer(a, name, 0);
        if (n[a] <= 0) card.fail(name, segment_node_needed(name));
      }
      s.segments.push_back(n);
      s.at.push_back(where_of(*r));
    }
    if (s.segments.empty()) head.fail("SID", fmt::format("segment set {} has no segments", sid));
    const auto [it, fresh] = segment_sets_.emplace(sid, std::move(s));
    if (!fresh)
      head.fail("SID", fmt::format("segment set {} is defined twice (first at {})", sid,
                                   it->second.head.str()));
  }

  // Any number of cards NSID (NID), DOF, VAD, LCID, SF, VID, DEATH, BIRTH (LS-DYNA
  // manual, *BOUNDARY_PRESCRIBED_MOTION), after the ID card of the _ID option. anvil
  // prescribes translations (DOF 1-3) by velocity (VAD 0) or displacement (VAD 2) from
  // BIRTH to DEATH (0, or LS-DYNA's "never" 1e28: to the end); anything else would run
  // another problem, so it is an error.
  void prescribed_motion(const Block& b, bool set) {
    Cursor c(b);
    if (ends_with(b.name, "_ID")) c.next();
    while (auto l = c.next_record()) {
      const Card card(b, *l, {10, 10, 10, 10, 10, 10, 10, 10});
      MotionCard m;
      (set ? m.set : m.node) = node_or_set_id(card, set);
      m.dof = translation_dof(card, "prescribes the translations x, y, z (DOF 1, 2, 3) of "
                                    "solid nodes");
      const auto vad = card.integer(2, "VAD", 0);
      if (vad != 0 && vad != 2)
        card.fail("VAD", fmt::format("VAD = {} is not supported: anvil prescribes a velocity "
                                     "(VAD 0) or a displacement (VAD 2)",
                                     vad));
      m.displacement = vad == 2;
      add_motion(b, card, *l, m);
    }
  }

  // The fields a prescribed motion card shares after DOF and VAD (LCID, SF, VID, DEATH,
  // BIRTH in fields 3-7), then m to the motions in card order.
  void add_motion(const Block& b, const Card& card, const Line& l, MotionCard& m) {
    m.lcid = card.integer(3, "LCID", 0);
    if (m.lcid <= 0) card.fail("LCID", "LCID must be the id of a *DEFINE_CURVE");
    m.sf = card.real(4, "SF", 1.0);
    const double death = card.real(6, "DEATH", 0);
    if (death != 0 && death < 1e20) m.death = death; // (LS-DYNA's "never" is 1e28)
    m.birth = card.real(7, "BIRTH", 0);
    if (m.birth < 0) card.fail("BIRTH", fmt::format("BIRTH = {} is negative", m.birth));
    if (!(m.death > m.birth))
      card.fail("DEATH", fmt::format("DEATH = {} is not after BIRTH = {}", m.death, m.birth));
    m.at = where_of(l);
    m.keyword = b.name;
    m.seq = card_seq_++;
    motions_.push_back(m);
  }

  // PID, DOF, VAD, LCID, SF, VID, DEATH, BIRTH (LS-DYNA manual,
  // *BOUNDARY_PRESCRIBED_MOTION_RIGID): the centre of mass (DOF 1-3) or the spin (DOF 5-7)
  // of a rigid part, anvil's condition on the body (`part:`).
  // PIDL, PIDS, IFLAG per card: part PIDS joins the body of part PIDL (both *MAT_RIGID).
  void constrained_rigid_bodies(const Block& b) {
    Cursor c(b);
    while (auto l = c.next_record()) {
      const Card card(b, *l, {10, 10, 10});
      RigidMerge m;
      m.lead = card.integer(0, "PIDL", 0);
      m.merged = card.integer(1, "PIDS", 0);
      if (m.lead <= 0) card.fail("PIDL", "PIDL must be a positive part id");
      if (m.merged <= 0) card.fail("PIDS", "PIDS must be a positive part id");
      if (m.lead == m.merged) card.fail("PIDS", "PIDS is PIDL: a part merges into another");
      const auto iflag = card.integer(2, "IFLAG", 0);
      if (iflag != 0 && iflag != 1) card.fail("IFLAG", "IFLAG must be 0 or 1");
      m.iflag = static_cast<int>(iflag);
      m.at = where_of(*l);
      rigid_merges_.push_back(m);
    }
  }

  void prescribed_motion_rigid(const Block& b) {
    Cursor c(b);
    if (ends_with(b.name, "_ID")) c.next();
    while (auto l = c.next_record()) {
      const Card card(b, *l, {10, 10, 10, 10, 10, 10, 10, 10});
      MotionCard m;
      m.pid = card.integer(0, "PID", 0);
      if (m.pid <= 0) card.fail("PID", "PID must be a positive part id");
      const auto dof = card.integer(1, "DOF", 0);
      if (!((dof >= 1 && dof <= 3) || (dof >= 5 && dof <= 7)))
        card.fail("DOF", fmt::format("DOF = {} is not supported: anvil prescribes the "
                                     "translations x, y, z (DOF 1, 2, 3) and the rotations about "
                                     "x, y, z (DOF 5, 6, 7) of a rigid body",
                                     dof));
      m.rotation = dof >= 5;
      m.dof = static_cast<int>(m.rotation ? dof - 5 : dof - 1);
      // VAD 2 on DOF 5-7: the angle (radians) about the global axis, the body turned by
      // the curve's change each step.
      const auto vad = card.integer(2, "VAD", 0);
      if (vad != 0 && vad != 2)
        card.fail("VAD", fmt::format("VAD = {} is not supported: anvil prescribes a velocity "
                                     "(VAD 0) or a displacement (VAD 2; of DOF 5-7, the angle "
                                     "in radians)",
                                     vad));
      card.integer(5, "VID", 0); // (a vector's id, unused for DOF 1-3 and 5-7: an id all the same)
      m.displacement = vad == 2;
      add_motion(b, card, *l, m);
    }
  }

  // LCID, SIDR, SFA, SFO, OFFA, OFFO, DATTYP, LCINT, then one point (A, O) per card in
  // fields of 20 columns; the offsets are applied before the scale factors (LS-DYNA
  // manual, *DEFINE_CURVE): t = SFA (A + OFFA), value = SFO (O + OFFO). Read only when a
  // motion, a load or a material names the curve (curve()): decks carry curves for
  // things anvil does not model, and those are no concern of the run.
  static CurveCard read_curve(const Block& b) {
    Cursor c(b);
    skip_title(b, c);
    const Line l = c.next();
    const Card c1(b, l, {10, 10, 10, 10, 10, 10, 10, 10});
    CurveCard cc;
    cc.lcid = c1.integer(0, "LCID", 0);
    cc.at = where_of(l);
    const auto sidr = c1.integer(1, "SIDR", 0);
    if (sidr == 1)
      c1.fail("SIDR", "SIDR = 1 (a curve for dynamic relaxation only) is not supported: anvil "
                      "has no dynamic relaxation phase");
    if (sidr != 0 && sidr != 2) c1.fail("SIDR", "SIDR must be 0, 1 or 2");
    // A scale factor of 0 is LS-DYNA's default, 1.
    const double sfa = c1.real(2, "SFA", 1) == 0 ? 1 : c1.real(2, "SFA", 1);
    const double sfo = c1.real(3, "SFO", 1) == 0 ? 1 : c1.real(3, "SFO", 1);
    const double offa = c1.real(4, "OFFA", 0), offo = c1.real(5, "OFFO", 0);
    if (c1.integer(6, "DATTYP", 0) != 0)
      c1.fail("DATTYP", "DATTYP other than 0 (a general curve) is not supported");
    while (auto p = c.next_record()) {
      const Card pt(b, *p, {20, 20, 20, 20});
      // A third value (a table's, or a point split wrongly) would be dropped unseen (QA
      // round 24): a point card holds A and O.
      for (int k = 2; k < pt.size(); ++k)
        if (!pt.blank(k))
          pt.fail(k == 2 ? "A2" : "O2", "a point card holds one point, A and O (in two fields "
                                        "of 20 columns): write one point per card");
      const double t = sfa * (pt.real(0, "A1") + offa);
      if (!cc.curve.t.empty() && !(t > cc.curve.t.back()))
        pt.fail("A1", fmt::format("the abscissae must increase from point to point: {} "
                                  "follows {}",
                                  t, cc.curve.t.back()));
      cc.curve.t.push_back(t);
      cc.curve.value.push_back(sfo * (pt.real(1, "O1") + offo));
    }
    if (cc.curve.t.empty()) c1.fail("LCID", fmt::format("curve {} has no points", cc.lcid));
    return cc;
  }

  // The LCID a *DEFINE_CURVE block gives, or 0 when its first card gives none: a curve no
  // motion names is never read, and need not be readable.
  static std::int64_t curve_id(const Block& b) {
    try {
      Cursor c(b);
      skip_title(b, c);
      const Line l = c.next();
      return Card(b, l, {10, 10, 10, 10, 10, 10, 10, 10}).integer(0, "LCID", 0);
    } catch (const InputError&) {
      return 0;
    }
  }

  // Whether a *DEFINE_CURVE gives curve `lcid`.
  bool curve_defined(std::int64_t lcid) {
    index_curves();
    return curves_.count(lcid) > 0 || curve_index_.count(lcid) > 0;
  }

  // The index of the *DEFINE_CURVE blocks by LCID, made at the first call.
  void index_curves() {
    if (curve_index_.empty())
      for (const Block* b : curve_blocks_) curve_index_.emplace(curve_id(*b), b);
  }

  // Curve `lcid`, read from the *DEFINE_CURVE that defines it (an index of the curves by
  // LCID, made at the first call); an error at `at` when none does, at the second when two
  // do.
  const CurveCard& curve(std::int64_t lcid, const SourceLocation& at) {
    if (const auto it = curves_.find(lcid); it != curves_.end()) return it->second;
    index_curves();
    const auto [first, last] = curve_index_.equal_range(lcid);
    if (first == last)
      throw InputError(at, fmt::format("curve {} is not defined (*DEFINE_CURVE)", lcid));
    CurveCard cc = read_curve(*first->second);
    if (std::next(first) != last)
      throw InputError(read_curve(*std::next(first)->second).at.loc("*DEFINE_CURVE.LCID"),
                       fmt::format("curve {} is defined twice (first at {})", lcid, cc.at.str()));
    return curves_.emplace(lcid, std::move(cc)).first->second;
  }

  // A warning for each pair of conditions that hold the same node components, not both
  // fixing them: the later card wins there (conditions apply in card order).
  static void warn_of_held_twice(const Config& c, const Mesh& mesh,
                                 std::vector<std::string>& warnings) {
    const auto& bcs = c.boundary_conditions;
    std::vector<std::array<int, 3>> holder(mesh.nodes.size(), {-1, -1, -1});
    std::map<std::pair<int, int>, std::int64_t> clashes; // (earlier, later) -> components
    // A rigid body's conditions (on its part) hold its six components (QA round 31: two
    // motion cards on one DOF went unsaid).
    std::map<std::string, std::array<int, 6>> body_holder;
    for (std::size_t b = 0; b < bcs.size(); ++b) {
      const auto& bc = bcs[b];
      if (!bc.nodes.name.empty()) continue;
      auto& holder6 =
          body_holder.try_emplace(*bc.nodes.part, std::array<int, 6>{-1, -1, -1, -1, -1, -1})
              .first->second;
      for (std::size_t i = 0; i < 6; ++i) {
        const bool on = i < 3 ? (bc.prescribed ? bc.components[i] : bc.fix[i])
                              : (bc.prescribed ? bc.spin_components[i - 3] : bc.fix_spin[i - 3]);
        if (!on) continue;
        int& h = holder6[i];
        if (h >= 0 && (bc.prescribed || bcs[static_cast<std::size_t>(h)].prescribed))
          ++clashes[{h, static_cast<int>(b)}];
        h = static_cast<int>(b);
      }
    }
    for (std::size_t b = 0; b < bcs.size(); ++b) {
      if (bcs[b].nodes.name.empty()) continue; // a rigid body's (its part): above
      const auto& on = bcs[b].prescribed ? bcs[b].components : bcs[b].fix;
      for (const std::int64_t n : mesh.node_sets.at(bcs[b].nodes.name))
        for (std::size_t i = 0; i < 3; ++i) {
          if (!on[i]) continue;
          int& h = holder[static_cast<std::size_t>(n)][i];
          if (h >= 0 && (bcs[b].prescribed || bcs[static_cast<std::size_t>(h)].prescribed))
            ++clashes[{h, static_cast<int>(b)}];
          h = static_cast<int>(b);
        }
    }
    for (const auto& [pair, count] : clashes)
      warnings.push_back(fmt::format(
          "{}: {} node component{} this card holds {} held by the card at {} too; the later "
          "card wins there (anvil applies constraints and motions in card order)",
          bcs[static_cast<std::size_t>(pair.second)].where.str(), count, count == 1 ? "" : "s",
          count == 1 ? "is" : "are", bcs[static_cast<std::size_t>(pair.first)].where.str()));
  }

  void velocity_generation(const Block& b) {
    Cursor c(b);
    while (!c.done()) {
      const Line l = c.next();
      const Card c1(b, l, {10, 10, 10, 10, 10, 10, 10, 10});
      VelocityGen v{};
      v.id = c1.integer(0, "ID", 0);
      const std::int64_t styp = c1.integer(1, "STYP", 0);
      if (styp < 1 || styp > 3)
        c1.fail("STYP", fmt::format("STYP must be 1 (part set), 2 (part) or 3 (node set), "
                                    "found {}",
                                    styp));
      v.styp = static_cast<int>(styp);
      if (v.id <= 0) c1.fail("ID", "ID must be a positive part or set id");
      const double omega = c1.real(2, "OMEGA");
      v.velocity = {c1.real(3, "VX"), c1.real(4, "VY"), c1.real(5, "VZ")};
      if (c1.integer(7, "ICID", 0) != 0)
        c1.fail("ICID", "velocities in a local coordinate system (ICID) are not supported");
      const Line l2 = c.next();
      const Card c2(b, l2, {10, 10, 10, 10, 10, 10, 10, 10});
      v.center = {c2.real(0, "XC"), c2.real(1, "YC"), c2.real(2, "ZC")};
      const Vec3 axis{c2.real(3, "NX"), c2.real(4, "NY"), c2.real(5, "NZ")};
      if (omega != 0) {
        const double len = norm(axis);
        if (!(len > 0))
          c2.fail("NX", "the rotation axis (NX, NY, NZ) must not be zero when OMEGA is given");
        v.angular = axis * (omega / len);
      }
      if (c2.integer(6, "PHASE", 0) != 0)
        warnings_.push_back(fmt::format("{}: PHASE = 1 (after dynamic relaxation): anvil has no "
                                        "dynamic relaxation and applies the velocity at t = 0",
                                        where_of(l2).str()));
      v.at = where_of(l);
      v.keyword = b.name;
      velocities_.push_back(v);
    }
  }

  void initial_velocity(const Block& b) {
    Cursor c(b);
    while (!c.done()) {
      const Line l = c.next();
      const Card c1(b, l, {10, 10, 10, 10, 10});
      VelocityGen v{};
      v.id = c1.id(0, "NSID");
      v.styp = v.id == 0 ? 0 : 3;
      if (c1.integer(1, "NSIDEX", 0) != 0)
        c1.fail("NSIDEX", "an exempted node set is not supported");
      if (c1.integer(2, "BOXID", 0) != 0) c1.fail("BOXID", "a box restriction is not supported");
      if (c1.integer(4, "ICID", 0) != 0)
        c1.fail("ICID", "velocities in a local coordinate system (ICID) are not supported");
      const Line l2 = c.next();
      const Card c2(b, l2, {10, 10, 10, 10, 10, 10});
      v.velocity = {c2.real(0, "VX"), c2.real(1, "VY"), c2.real(2, "VZ")};
      if (c2.real(3, "VXR") != 0 || c2.real(4, "VYR") != 0 || c2.real(5, "VZR") != 0)
        warnings_.push_back(fmt::format("{}: the rotational velocities VXR, VYR, VZR are ignored "
                                        "(solid nodes have no rotations; use "
                                        "*INITIAL_VELOCITY_GENERATION for a spin)",
                                        where_of(l2).str()));
      v.at = where_of(l);
      v.keyword = b.name;
      velocities_.push_back(v);
    }
  }

  // *INITIAL_VELOCITY_NODE: any number of cards NID, VX, VY, VZ, VXR, VYR, VZR. The nodes
  // of one velocity are one initial condition (a node given twice in the keyword takes its
  // last card's), at the keyword's place among the others.
  void initial_velocity_node(const Block& b) {
    Cursor c(b);
    std::map<std::int64_t, std::pair<Vec3, Where>> last; // node id -> its velocity
    bool rotations = false;
    while (auto l = c.next_record()) {
      const Card card(b, *l, {10, 10, 10, 10, 10, 10, 10});
      const std::int64_t nid = card.integer(0, "NID", 0);
      if (nid <= 0) card.fail("NID", fmt::format("NID must be a positive node id, found {}", nid));
      last[nid] = {Vec3{card.real(1, "VX"), card.real(2, "VY"), card.real(3, "VZ")}, where_of(*l)};
      rotations = rotations || card.real(4, "VXR") != 0 || card.real(5, "VYR") != 0 ||
                  card.real(6, "VZR") != 0;
    }
    if (rotations)
      warnings_.push_back(fmt::format("{}: *INITIAL_VELOCITY_NODE: the rotational velocities "
                                      "VXR, VYR, VZR are ignored (solid nodes and particles "
                                      "have no rotations)",
                                      where_of(b.head).str()));
    std::map<std::array<double, 3>, VelocityGen> groups; // by velocity
    for (const auto& [nid, vw] : last) {
      auto [it, fresh] =
          groups.try_emplace(std::array<double, 3>{vw.first.x, vw.first.y, vw.first.z});
      VelocityGen& v = it->second;
      if (fresh) {
        v.styp = 4;
        v.velocity = vw.first;
        v.at = vw.second;
        v.keyword = b.name;
      }
      v.nodes.push_back(nid);
      v.node_at.push_back(vw.second);
    }
    for (auto& [vel, v] : groups) velocities_.push_back(std::move(v));
  }

  // PID, VX, VY, VZ, VXR, VYR, VZR, LCID (LS-DYNA manual, *INITIAL_VELOCITY_RIGID_BODY):
  // the translational and rotational velocities of a rigid part at its centre of mass,
  // anvil's initial condition on the part about `center: mass_center`.
  void initial_velocity_rigid_body(const Block& b) {
    Cursor c(b);
    while (!c.done()) {
      const Line l = c.next();
      const Card c1(b, l, {10, 10, 10, 10, 10, 10, 10, 10});
      VelocityGen v{};
      v.id = c1.integer(0, "PID", 0);
      if (v.id <= 0) c1.fail("PID", "PID must be a positive part id");
      v.styp = 2;
      v.velocity = {c1.real(1, "VX"), c1.real(2, "VY"), c1.real(3, "VZ")};
      v.angular = {c1.real(4, "VXR"), c1.real(5, "VYR"), c1.real(6, "VZR")};
      if (c1.integer(7, "LCID", 0) != 0)
        c1.fail("LCID", "a curve of the rotational velocity (LCID) is not supported");
      v.mass_center = true;
      v.at = where_of(l);
      v.keyword = b.name;
      velocities_.push_back(v);
    }
  }

  // The *CONTACT_ forms anvil reads (with or without _ID or _TITLE): 1 a single surface,
  // 2 two surfaces (slave and master sides), 0 none. All become anvil's general contact.
  // The options of a contact keyword's name: the _ID (or _TITLE) card and the _MPP cards,
  // in either order of the suffixes.
  struct ContactOptions {
    bool id = false, mpp = false;
  };
  static ContactOptions contact_options(std::string_view& n) {
    ContactOptions o;
    for (int k = 0; k < 2; ++k) {
      if (!o.mpp && ends_with(n, "_MPP")) {
        n.remove_suffix(4);
        o.mpp = true;
      } else if (!o.id && ends_with(n, "_ID")) {
        n.remove_suffix(3);
        o.id = true;
      } else if (!o.id && ends_with(n, "_TITLE")) {
        n.remove_suffix(6);
        o.id = true;
      }
    }
    return o;
  }

  static int contact_form(std::string_view n) {
    if (!starts_with(n, "CONTACT_")) return 0;
    n.remove_prefix(8);
    contact_options(n);
    for (const char* f : {"AUTOMATIC_SINGLE_SURFACE", "SINGLE_SURFACE", "ERODING_SINGLE_SURFACE",
                          "AUTOMATIC_GENERAL"})
      if (n == f) return 1;
    for (const char* f :
         {"AUTOMATIC_SURFACE_TO_SURFACE", "SURFACE_TO_SURFACE", "ERODING_SURFACE_TO_SURFACE",
          "AUTOMATIC_NODES_TO_SURFACE", "NODES_TO_SURFACE", "ERODING_NODES_TO_SURFACE",
          "AUTOMATIC_ONE_WAY_SURFACE_TO_SURFACE", "ONE_WAY_SURFACE_TO_SURFACE"})
      if (n == f) return 2;
    return 0;
  }

  // A side of a contact (SSID with SSTYP, MSID with MSTYP): parts or a part set, or all
  // parts (id 0, or type 5).
  static void contact_side(const Card& c1, int id_field, const char* id_name, int type_field,
                           const char* type_name, bool required, std::int64_t& id,
                           std::int64_t& type) {
    id = c1.id(id_field, id_name);
    type = c1.integer(type_field, type_name, 0);
    if (type == 5) id = 0; // "include all"
    if (id == 0 && required && type != 5)
      c1.fail(id_name, fmt::format("{} is blank: a two-surface contact needs its {} side", id_name,
                                   id_field == 0 ? "slave" : "master"));
    if (id != 0 && type != 2 && type != 3)
      c1.fail(type_name,
              fmt::format("{} = {} is not supported: anvil's contact is among parts; give a part "
                          "set (2), a part (3) or all parts (5{})",
                          type_name, type,
                          type == 4 ? "; a node set's nodes belong to parts: list those" : ""));
  }

  void contact(const Block& b) {
    Cursor c(b);
    std::string_view name = b.name;
    const ContactOptions options = contact_options(name);
    if (options.id) c.next(); // CID and HEADING
    if (options.mpp) {
      // MPP 1 (IGNORE, BCKT, LCBCKT, NS2TRK, INITITR, PARMAX, CPARM8: the decomposition's
      // search and the treatment of initial penetrations, which anvil's contact does its
      // own way, docs/contact.md), then MPP 2 when the next line opens with a lone '&'.
      c.next();
      if (const auto l = c.peek(); l && !l->text.empty() && l->text.front() == '&' &&
                                   (l->text.size() == 1 || l->text[1] == ' ' || l->text[1] == ','))
        c.next();
    }
    const Line l = c.next();
    const Card c1(b, l, {10, 10, 10, 10, 10, 10, 10, 10});
    ContactCard k{};
    k.two_surface = contact_form(b.name) == 2;
    try {
      contact_side(c1, 0, "SSID", 2, "SSTYP", k.two_surface, k.ssid, k.sstyp);
      if (k.two_surface) contact_side(c1, 1, "MSID", 3, "MSTYP", true, k.msid, k.mstyp);
    } catch (const InputError& e) {
      if (!options.mpp) throw;
      // An _MPP contact whose MPP card is missing reads card 1 as it (QA round 33).
      const std::string what = e.what(), prefix = e.where().str() + ": ";
      throw InputError(e.where(), (what.rfind(prefix, 0) == 0 ? what.substr(prefix.size()) : what) +
                                      " (an _MPP contact has its MPP card before card 1, after "
                                      "the _ID card: is it missing?)");
    }
    if (c1.integer(4, "SBOXID", 0) != 0)
      c1.fail("SBOXID", "a box restriction (SBOXID) is not supported");
    if (k.two_surface && c1.integer(5, "MBOXID", 0) != 0)
      c1.fail("MBOXID", "a box restriction (MBOXID) is not supported");
    const Line l2 = c.next();
    const Card c2(b, l2, {10, 10, 10, 10, 10, 10, 10, 10});
    k.fs = c2.real(0, "FS");
    k.fd = c2.real(1, "FD");
    k.dc = c2.real(2, "DC");
    k.vdc = c2.real(4, "VDC");
    k.bt = c2.real(6, "BT");
    k.dt = c2.real(7, "DT", 0);
    if (k.fs < 0) c2.fail("FS", "the friction coefficient FS must not be negative");
    const Line l3 = c.next();
    const Card c3(b, l3, {10, 10, 10, 10, 10, 10, 10, 10});
    k.sfs = c3.real(0, "SFS", 1);
    if (k.sfs == 0) k.sfs = 1; // LS-DYNA's default
    if (k.sfs < 0) c3.fail("SFS", "the penalty scale SFS must be positive");
    k.sfm = c3.real(1, "SFM", 1);
    if (k.sfm == 0) k.sfm = 1;
    if (k.sfm < 0) c3.fail("SFM", "the penalty scale SFM must be positive");
    // The eroding forms' own card (ISYM, EROSOP, IADJ): anvil's contact always follows the
    // faces that erosion uncovers (docs/contact.md).
    if (b.name.find("ERODING") != std::string::npos) c.next();
    optional_cards(b, c, 7, true); // optional cards A to G
    k.at = where_of(l);
    k.keyword = b.name;
    contacts_.push_back(k);
  }

  void control_contact(const Block& b) {
    Cursor c(b);
    const Line l = c.next();
    const Card card(b, l, {10, 10});
    slsfac_ = card.real(0, "SLSFAC", 0);
    if (slsfac_ < 0) card.fail("SLSFAC", "SLSFAC must not be negative");
    rwpnal_ = card.real(1, "RWPNAL", 0);
    // Card 2 and optional cards 3-7 tune LS-DYNA's contact algorithms, as do the other
    // fields of card 1; anvil's contact has no such switches.
    optional_cards(b, c, 6, false);
  }

  void rigidwall(const Block& b) {
    Cursor c(b);
    if (ends_with(b.name, "_ID")) c.next(); // RWID and HEADING
    const Line l = c.next();
    const Card c1(b, l, {10, 10, 10, 10, 10, 10, 10});
    WallCard w{};
    w.nsid = c1.id(0, "NSID");
    w.nsidex = c1.id(1, "NSIDEX");
    w.boxid = c1.id(2, "BOXID");
    w.offset = c1.real(3, "OFFSET");
    w.birth = c1.real(4, "BIRTH");
    w.death = c1.real(5, "DEATH", 0);
    const Line l2 = c.next();
    const Card c2(b, l2, {10, 10, 10, 10, 10, 10, 10, 10});
    w.tail = {c2.real(0, "XT"), c2.real(1, "YT"), c2.real(2, "ZT")};
    w.head = {c2.real(3, "XH"), c2.real(4, "YH"), c2.real(5, "ZH")};
    w.fric = c2.real(6, "FRIC");
    w.wvel = c2.real(7, "WVEL");
    if (!(norm(w.head - w.tail) > 0))
      c2.fail("XH", "the head (XH, YH, ZH) must differ from the tail (XT, YT, ZT): they give "
                    "the wall's normal");
    if (w.fric < 0) c2.fail("FRIC", "FRIC must not be negative");
    w.at = where_of(l);
    walls_.push_back(w);
  }

  // ---- controls and output ---------------------------------------------------------------

  void control_termination(const Block& b) {
    Cursor c(b);
    const Line l = c.next();
    const Card card(b, l, {10, 10, 10, 10, 10, 10});
    endtim_ = card.real(0, "ENDTIM");
    endcyc_ = card.integer(1, "ENDCYC", 0);
    if (endtim_ < 0) card.fail("ENDTIM", "ENDTIM must not be negative");
    if (endcyc_ < 0) card.fail("ENDCYC", "ENDCYC must not be negative");
    // DTMIN: the run stops when the step falls below DTMIN times the initial one (anvil's
    // time_step.minimum_fraction; LS-DYNA writes a restart dump there, anvil a checkpoint).
    dtmin_ = card.real(2, "DTMIN", 0);
    if (!(dtmin_ >= 0 && dtmin_ < 1))
      card.fail("DTMIN", "DTMIN must be in [0, 1): a fraction of the initial time step");
    if (card.real(3, "ENDENG", 0) != 0)
      warnings_.push_back(fmt::format("{}: ENDENG (stop at a change of the total energy) is "
                                      "ignored: the run goes on to ENDTIM or ENDCYC",
                                      where_of(l).str()));
    if (card.real(4, "ENDMAS", 0) != 0)
      warnings_.push_back(fmt::format("{}: ENDMAS (stop at a mass increase of mass scaling) is "
                                      "ignored: anvil adds mass once, at t = 0, and reports it "
                                      "(`anvil check`, summary.json)",
                                      where_of(l).str()));
    if (card.integer(5, "NOSOL", 0) != 0)
      card.fail("NOSOL", "NOSOL (a run that reads the deck and writes no solution) is not "
                         "supported: use `anvil check`");
    termination_at_ = where_of(l);
    have_termination_ = true;
  }

  void control_timestep(const Block& b) {
    Cursor c(b);
    const Line l = c.next();
    const Card card(b, l, {10, 10, 10, 10, 10, 10, 10, 10});
    // (A repeated *CONTROL_TIMESTEP replaces the earlier one whole: its blank TSSFAC is
    // LS-DYNA's 0.9, and the earlier card's notes go; QA round 30.)
    timestep_notes_.clear();
    const double tssfac = card.real(1, "TSSFAC", 0);
    tssfac_ = 0.9;
    if (tssfac != 0) {
      if (!(tssfac > 0 && tssfac <= 1))
        card.fail("TSSFAC", "TSSFAC must be in (0, 1]: a fraction of the stable time step");
      tssfac_ = tssfac;
    }
    // DT2MS < 0: mass scaling, anvil's time_step.mass_scaling with the step TSSFAC |DT2MS|,
    // scaled once at t = 0 (LS-DYNA's MS1ST = 1; its default rescales every cycle).
    // DT2MS > 0 (mass added to and taken from every element): not supported.
    const double dt2ms = card.real(4, "DT2MS", 0);
    mass_scaling_dt2ms_ = 0;
    mass_scaling_at_ = where_of(l).loc("*" + b.name + ".DT2MS");
    if (!std::isfinite(dt2ms)) card.fail("DT2MS", "DT2MS must be a finite number");
    const auto ms1st = card.integer(7, "MS1ST", 0);
    if (ms1st != 0 && ms1st != 1) card.fail("MS1ST", "MS1ST must be 0 or 1");
    if (dt2ms > 0)
      timestep_notes_.push_back(
          fmt::format("{}: DT2MS > 0 (mass added to and taken from every "
                      "element) is ignored: anvil takes the stable time step of "
                      "the unscaled mass (DT2MS < 0, mass added where needed, "
                      "is supported)",
                      where_of(l).str()));
    if (dt2ms < 0) {
      mass_scaling_dt2ms_ = -dt2ms;
      if (ms1st == 0)
        timestep_notes_.push_back(fmt::format(
            "{}: DT2MS < 0: anvil adds the mass once, at t = 0, to the elements at rest in their "
            "initial shape (LS-DYNA's MS1ST = 1); LS-DYNA's default (MS1ST = 0) adds mass every "
            "cycle, so that crushed elements keep the step TSSFAC |DT2MS|, where in anvil their "
            "step falls below it",
            where_of(l).str()));
    }
    if (card.integer(5, "LCTM", 0) != 0)
      timestep_notes_.push_back(
          fmt::format("{}: LCTM (a time step limit curve) is ignored", where_of(l).str()));
    optional_cards(b, c, 1, true); // card 2: mass scaling options
  }

  void control_hourglass(const Block& b) {
    Cursor c(b);
    const Line l = c.next();
    const Card card(b, l, {10, 10});
    control_ihq_ = card.integer(0, "IHQ", 0);
    control_qh_ = card.real(1, "QH");
    check_hourglass(card, control_ihq_, "IHQ", control_qh_, "QH");
  }

  void control_bulk_viscosity(const Block& b) {
    Cursor c(b);
    const Line l = c.next();
    const Card card(b, l, {10, 10, 10, 10});
    control_q1_ = card.real(0, "Q1");
    control_q2_ = card.real(1, "Q2");
    if (control_q1_ < 0) card.fail("Q1", "Q1 must not be negative");
    if (control_q2_ < 0) card.fail("Q2", "Q2 must not be negative");
  }

  // *DATABASE_BINARY_D3DUMP, *DATABASE_BINARY_RUNRSF: CYCL, the cycles between restart
  // dumps: anvil's checkpoints (`checkpoint: {cycles: N}`), every CYCL cycles (the smaller
  // of the two keywords').
  void restart_dump(const Block& b) {
    Cursor c(b);
    const Line l = c.next();
    const Card card(b, l, {10, 10, 10, 10});
    const double cycl = card.real(0, "CYCL");
    if (cycl < 0 || cycl != std::floor(cycl) || cycl > 9e15)
      card.fail("CYCL", fmt::format("CYCL must be a whole number of cycles, found {}", cycl));
    if (cycl == 0) return;
    const auto n = static_cast<std::int64_t>(cycl);
    if (checkpoint_cycles_ == 0 || n < checkpoint_cycles_) checkpoint_cycles_ = n;
  }

  void d3plot(const Block& b) {
    Cursor c(b);
    const Line l = c.next();
    const Card card(b, l, {10, 10, 10, 10, 10});
    const double dt = card.real(0, "DT");
    if (dt < 0) card.fail("DT", "DT must not be negative");
    d3plot_dt_ = dt;
    d3plot_states_ = card.integer(3, "NPLTC", 0);
    if (d3plot_states_ < 0) card.fail("NPLTC", "NPLTC must not be negative");
    // Output times and contents only: the run is the same, so a warning, not an error.
    if (card.integer(1, "LCDT", 0) != 0)
      warnings_.push_back(fmt::format("{}: *DATABASE_BINARY_D3PLOT: LCDT (a curve of output "
                                      "intervals) is ignored: fields are written every {}",
                                      where_of(l).str(),
                                      d3plot_states_ > 0 ? "ENDTIM/NPLTC" : "DT"));
    if (card.integer(4, "PSETID", 0) != 0)
      warnings_.push_back(fmt::format("{}: *DATABASE_BINARY_D3PLOT: PSETID is ignored: every "
                                      "part is written",
                                      where_of(l).str()));
    optional_cards(b, c, 1, false); // card 2: d3plot file options (IOOPT, RATE, ...)
  }

  void history_interval(const Block& b) {
    Cursor c(b);
    const Line l = c.next();
    const Card card(b, l, {10});
    const double dt = card.real(0, "DT");
    if (dt < 0) card.fail("DT", "DT must not be negative");
    if (dt > 0) history_dt_ = history_dt_ > 0 ? std::min(history_dt_, dt) : dt;
  }

  // *DATABASE_HISTORY_NODE (node ids) or _SET (node set ids), any number per card.
  void history_nodes(const Block& b, bool sets) {
    Cursor c(b);
    while (auto l = c.next_record()) {
      const Card card(b, *l, {10, 10, 10, 10, 10, 10, 10, 10}, Card::Extra::keep);
      for (int k = 0; k < card.size(); ++k)
        if (const auto id = card.id(k, fmt::format("ID{}", k + 1)); id != 0)
          history_nodes_.push_back({id, sets, where_of(*l), "*" + b.name});
    }
  }

  // *DATABASE_HISTORY_NODE_ID: one node per card, its ID and a HEADING (not used).
  void history_nodes_id(const Block& b) {
    Cursor c(b);
    while (auto l = c.next_record()) {
      const Card card(b, *l, {10, 70}, Card::Extra::keep);
      if (const auto id = card.id(0, "ID"); id != 0)
        history_nodes_.push_back({id, false, where_of(*l), "*" + b.name});
    }
  }

  // *DATABASE_HISTORY_SOLID (element ids, any number per card) or _ID (one element per
  // card, its ID and a HEADING, not used).
  void history_solids(const Block& b, bool with_heading) {
    Cursor c(b);
    while (auto l = c.next_record()) {
      if (with_heading) {
        const Card card(b, *l, {10, 70}, Card::Extra::keep);
        if (const auto id = card.id(0, "ID"); id != 0)
          history_solids_.push_back({id, false, where_of(*l), "*" + b.name});
        continue;
      }
      const Card card(b, *l, {10, 10, 10, 10, 10, 10, 10, 10}, Card::Extra::keep);
      for (int k = 0; k < card.size(); ++k)
        if (const auto id = card.id(k, fmt::format("ID{}", k + 1)); id != 0)
          history_solids_.push_back({id, false, where_of(*l), "*" + b.name});
    }
  }

  // ---- assembly ---------------------------------------------------------------------------

  std::int64_t node_position(std::int64_t nid, const Where& at, const std::string& key,
                             const std::string& what) const {
    const auto it = node_index_.find(nid);
    if (it == node_index_.end())
      throw InputError(at.loc(key),
                       fmt::format("{} refers to node {}, which no *NODE defines", what, nid));
    return it->second;
  }

  // Member set `member` of the _ADD set `sid` (s) among `sets` (of `kind`, "node" or
  // "part"), `depth` sets down: an undefined member, or a chain deeper than any deck's (a
  // set that includes itself), is an error at DSID.
  static const IdSet& united(const std::map<std::int64_t, IdSet>& sets, const char* kind,
                             std::int64_t sid, const IdSet& s, std::int64_t member, int depth) {
    const auto it = sets.find(member);
    if (it == sets.end())
      throw InputError(
          s.at.loc("*" + s.keyword + ".DSID"),
          fmt::format("{} set {} unites {} set {}, which is not defined", kind, sid, kind, member));
    if (depth > 64)
      throw InputError(
          s.at.loc("*" + s.keyword + ".DSID"),
          fmt::format("{} set {} includes itself (through *{})", kind, sid, s.keyword));
    return it->second;
  }

  // Node positions of a *SET_NODE_LIST (sorted, unique); every id must be a node.
  std::vector<std::int64_t> resolve_node_set(std::int64_t sid, const IdSet& s,
                                             int depth = 0) const {
    std::vector<std::int64_t> out;
    for (const auto member : s.sets) { // *SET_NODE_ADD
      const auto more =
          resolve_node_set(member, united(node_sets_, "node", sid, s, member, depth), depth + 1);
      out.insert(out.end(), more.begin(), more.end());
    }
    for (const auto id : s.ids)
      out.push_back(node_position(id, s.at, "*SET_NODE_LIST", fmt::format("node set {}", sid)));
    if (!s.ranges.empty())
      for (std::size_t i = 0; i < node_ids_.size(); ++i)
        for (const auto& [lo, hi] : s.ranges)
          if (node_ids_[i] >= lo && node_ids_[i] <= hi) {
            out.push_back(static_cast<std::int64_t>(i));
            break;
          }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  // The mesh: every node in file order, one block per part in `pids` order, node sets.
  Mesh build_mesh(const std::vector<std::int64_t>& pids, bool parts_must_exist) const {
    Mesh m;
    m.nodes = nodes_;
    m.node_ids = node_ids_;
    std::unordered_map<std::int64_t, std::size_t> block_of;
    for (const auto pid : pids) {
      block_of.emplace(pid, m.blocks.size());
      m.blocks.push_back(ElementBlock{fmt::format("part{}", pid), {}, {}});
    }
    for (const auto& e : elements_) {
      const auto b = block_of.find(e.pid);
      if (b == block_of.end()) {
        if (parts_must_exist)
          throw InputError(
              e.at.loc("*ELEMENT_SOLID.PID"),
              fmt::format("element {} belongs to part {}, which no *PART defines", e.eid, e.pid));
        continue;
      }
      Hex h;
      for (int a = 0; a < 8; ++a)
        h[a] = node_position(e.nodes[a], e.at, fmt::format("*ELEMENT_SOLID.N{}", a + 1),
                             fmt::format("element {}", e.eid));
      // An inverted element is named at its own card (the model's check would name the
      // part's, not knowing the file's lines).
      std::array<Vec3, 8> x;
      for (int a = 0; a < 8; ++a) x[a] = nodes_[static_cast<std::size_t>(h[a])];
      if (const double v = hex_volume(x); !(v > 0))
        throw InputError(e.at.loc("*ELEMENT_SOLID"),
                         fmt::format("element {} of part {} has a non-positive volume ({:.3g} "
                                     "m^3): check the node order",
                                     e.eid, part_name(e.pid), v));
      else if (!(hex_centre_jacobian(x) > 0))
        throw InputError(e.at.loc("*ELEMENT_SOLID"),
                         fmt::format("element {} of part {} is tangled: its volume is positive "
                                     "({:.3g} m^3) but its Jacobian at the centre is not: "
                                     "check the node order",
                                     e.eid, part_name(e.pid), v));
      m.blocks[b->second].elements.push_back(h);
      m.blocks[b->second].ids.push_back(e.eid);
    }
    for (const auto& [sid, s] : node_sets_)
      m.node_sets[fmt::format("nodeset_{}", sid)] = resolve_node_set(sid, s);
    return m;
  }

  std::string part_name(std::int64_t pid) const { return fmt::format("part{}", pid); }
  // The name of part `pid`, which a card naming a rigid body at `at` (`why`: what the card
  // does with it) must give: defined, of *MAT_RIGID, with solid elements.
  std::string rigid_part(std::int64_t pid, const SourceLocation& at, const std::string& why) const {
    const auto p =
        std::find_if(parts_.begin(), parts_.end(), [&](const PartCard& q) { return q.pid == pid; });
    if (p == parts_.end()) throw InputError(at, fmt::format("part {} is not defined (*PART)", pid));
    const auto m = materials_.find(p->mid);
    if (m == materials_.end() || !m->second.rigid ||
        std::none_of(elements_.begin(), elements_.end(),
                     [&](const auto& e) { return e.pid == pid; }))
      throw InputError(at, fmt::format("part {} is not rigid (*MAT_RIGID solids): {}", pid, why));
    return part_name(pid);
  }

  // The part ids of part set sid (listed, in ranges, and of the sets it unites).
  std::vector<std::int64_t> part_set_ids(std::int64_t sid, const IdSet& s, int depth) const {
    std::vector<std::int64_t> pids = s.ids;
    for (const auto& p : parts_)
      for (const auto& [lo, hi] : s.ranges)
        if (p.pid >= lo && p.pid <= hi) pids.push_back(p.pid);
    for (const auto member : s.sets) { // *SET_PART_ADD
      const auto more =
          part_set_ids(member, united(part_sets_, "part", sid, s, member, depth), depth + 1);
      pids.insert(pids.end(), more.begin(), more.end());
    }
    return pids;
  }

  // The parts of a part set, those anvil keeps (parts with solid elements or particles).
  std::vector<std::string> part_set(std::int64_t sid, const Where& at, const std::string& key,
                                    const std::set<std::int64_t>& kept) const {
    const auto it = part_sets_.find(sid);
    if (it == part_sets_.end())
      throw InputError(at.loc(key),
                       fmt::format("part set {} is not defined (*SET_PART_LIST)", sid));
    const std::vector<std::int64_t> pids = part_set_ids(sid, it->second, 0);
    std::vector<std::string> out;
    for (const auto pid : pids) {
      if (std::none_of(parts_.begin(), parts_.end(),
                       [&](const PartCard& p) { return p.pid == pid; }))
        throw InputError(
            it->second.at.loc("*SET_PART_LIST"),
            fmt::format("part set {} lists part {}, which no *PART defines", sid, pid));
      if (kept.count(pid) && std::find(out.begin(), out.end(), part_name(pid)) == out.end())
        out.push_back(part_name(pid));
    }
    return out;
  }

  // The particle sets of the parts `pids` (with *ELEMENT_SPH particles) into c.particles
  // and `lists` (their lists, still open for the node sets), `particle_of` where each
  // particle's node went. `material`: the part's material name (config()).
  void particle_sets(Config& c, const std::vector<std::int64_t>& pids,
                     const std::function<std::string(const PartCard&, bool)>& material,
                     const std::vector<char>& in_solid,
                     std::vector<std::shared_ptr<ParticleList>>& lists,
                     std::unordered_map<std::int64_t, ParticleAt>& particle_of,
                     std::vector<std::string>& warnings) const {
    std::map<std::int64_t, std::size_t> set_of_part;
    for (const auto pid : pids) {
      const PartCard& p = *std::find_if(parts_.begin(), parts_.end(),
                                        [&](const PartCard& q) { return q.pid == pid; });
      const auto sec = sph_sections_.find(p.secid);
      if (sec == sph_sections_.end()) {
        const auto solid = sections_.find(p.secid);
        const auto other = other_sections_.find(p.secid);
        const SectionCard* found = solid != sections_.end()         ? &solid->second
                                   : other != other_sections_.end() ? &other->second
                                                                    : nullptr;
        throw InputError(
            p.at.loc("*PART.SECID"),
            found
                ? fmt::format("part {} has SPH particles but its section {} is a *{} (at {}), "
                              "not a *SECTION_SPH",
                              p.pid, p.secid, found->keyword, found->at.str())
                : fmt::format("part {}: section {} is not defined (*SECTION_SPH)", p.pid, p.secid));
      }
      ParticleSetConfig ps;
      ps.name = part_name(p.pid);
      ps.where = p.at.loc("*PART");
      ps.material = material(p, true);
      ps.smoothing_ratio = sec->second.cslh;
      ps.smoothing_length = sec->second.sphini;
      ps.smoothing_where =
          sec->second.at.loc(sec->second.sphini > 0 ? "*SECTION_SPH.SPHINI" : "*SECTION_SPH.CSLH");
      // LS-DYNA's SPH has no artificial stress (Gray, Monaghan and Swift's remedy for the
      // tensile instability, on by default in a YAML deck): off, as there.
      ps.artificial_stress = 0;
      ps.h_min = sec->second.hmin;
      ps.h_max = sec->second.hmax;
      ps.corrected_gradient = sph_corrected_;
      // LS-DYNA's particles take their Monaghan viscosity from the bulk viscosity cards:
      // Q1 the quadratic coefficient (beta), Q2 the linear one (alpha); its defaults 1.5
      // and 0.06.
      const HourglassCard h = hourglass_card_of(p);
      ps.viscosity_quadratic = h.q1 > 0 ? h.q1 : 1.5;
      ps.viscosity_linear = h.q2 > 0 ? h.q2 : 0.06;
      if (const auto& mc = materials_.at(p.mid); mc.failure_strain > 0)
        warnings.push_back(fmt::format("{}: part {}: the failure strain of material {} is not "
                                       "used: anvil's particles do not erode",
                                       p.at.str(), p.pid, p.mid));
      set_of_part[pid] = c.particles.size();
      lists.push_back(std::make_shared<ParticleList>());
      ps.list = lists.back();
      c.particles.push_back(std::move(ps));
    }
    // NEND generates the particles at every node with an id from NID to NEND.
    std::vector<std::pair<std::int64_t, std::int64_t>> by_id; // (node id, position)
    if (std::any_of(sph_elements_.begin(), sph_elements_.end(),
                    [](const RawSph& e) { return e.nend != 0; })) {
      for (std::size_t i = 0; i < node_ids_.size(); ++i)
        by_id.emplace_back(node_ids_[i], static_cast<std::int64_t>(i));
      std::sort(by_id.begin(), by_id.end());
    }
    for (const auto& e : sph_elements_) {
      const auto set = set_of_part.find(e.pid);
      if (set == set_of_part.end())
        throw InputError(
            e.at.loc("*ELEMENT_SPH.PID"),
            fmt::format("particle {} belongs to part {}, which no *PART defines", e.nid, e.pid));
      ParticleList& list = *lists[set->second];
      auto add = [&](std::int64_t pos) {
        const std::int64_t nid = node_ids_[static_cast<std::size_t>(pos)];
        if (in_solid[static_cast<std::size_t>(pos)])
          throw InputError(e.at.loc("*ELEMENT_SPH.NID"),
                           fmt::format("node {} is a solid element's node: a particle needs a "
                                       "node of its own",
                                       nid));
        const auto [it, fresh] = particle_of.emplace(
            pos, ParticleAt{set->second, static_cast<std::int64_t>(list.x.size()), &e});
        if (!fresh)
          throw InputError(e.at.loc("*ELEMENT_SPH.NID"),
                           fmt::format("node {} has a particle already (at {})", nid,
                                       it->second.card->at.str()));
        list.x.push_back(nodes_[static_cast<std::size_t>(pos)]);
        list.mass.push_back(e.mass);
        list.volume.push_back(e.volume);
        list.id.push_back(nid);
      };
      if (e.nend == 0) {
        add(node_position(e.nid, e.at, "*ELEMENT_SPH.NID", fmt::format("particle {}", e.nid)));
        continue;
      }
      const auto lo =
          std::lower_bound(by_id.begin(), by_id.end(), std::pair{e.nid, std::int64_t{-1}});
      const auto hi = std::upper_bound(by_id.begin(), by_id.end(),
                                       std::pair{e.nend, std::numeric_limits<std::int64_t>::max()});
      if (lo == hi)
        throw InputError(e.at.loc("*ELEMENT_SPH.NEND"),
                         fmt::format("no node has an id from {} to {}", e.nid, e.nend));
      for (auto it = lo; it != hi; ++it) add(it->second);
    }
    warnings.insert(warnings.end(), sph_notes_.begin(), sph_notes_.end());
    warnings.insert(warnings.end(), sph_control_notes_.begin(), sph_control_notes_.end());
  }

  // The hourglass and bulk viscosity of part p: its *HOURGLASS, else the *CONTROL_ cards
  // (q1, q2 0: not given).
  HourglassCard hourglass_card_of(const PartCard& p) const {
    HourglassCard h{control_ihq_, control_qh_, control_q1_, control_q2_, p.at};
    if (p.hgid == 0) return h;
    const auto it = hourglass_.find(p.hgid);
    if (it == hourglass_.end())
      throw InputError(p.at.loc("*PART.HGID"), fmt::format("part {}: hourglass {} is not defined "
                                                           "(*HOURGLASS)",
                                                           p.pid, p.hgid));
    h.ihq = it->second.ihq;
    h.qm = it->second.qm;
    if (it->second.q1 > 0) h.q1 = it->second.q1;
    if (it->second.q2 > 0) h.q2 = it->second.q2;
    return h;
  }

  // The Mie-Gruneisen parameters of anvil's particles (`eos: mie_gruneisen`) from an
  // *EOS_GRUNEISEN: its linear Us-up Hugoniot (C, S1) and GAMA0, which is LS-DYNA's form
  // with S2 = S3 = A = 0 (E, LS-DYNA's energy per initial volume, is rho0 e).
  static ParamValues gruneisen_params(const EosCard& e) {
    auto fail = [&](const Where& at, const char* field, const std::string& why) {
      throw InputError(at.loc(fmt::format("*{}.{}", e.keyword, field)), why);
    };
    if (!(e.c > 0)) fail(e.at, "C", fmt::format("C must be positive, found {}", e.c));
    if (e.s1 < 0) fail(e.at, "S1", fmt::format("S1 must not be negative, found {}", e.s1));
    if (e.gamma0 < 0)
      fail(e.at, "GAMAO", fmt::format("GAMAO must not be negative, found {}", e.gamma0));
    for (const auto& [v, f] : {std::pair{e.s2, "S2"}, std::pair{e.s3, "S3"}})
      if (v != 0)
        fail(e.at, f,
             fmt::format("{} = {}: anvil's Mie-Gruneisen has a linear Us-up Hugoniot "
                         "(C, S1); S2 and S3 must be 0",
                         f, v));
    if (e.a != 0)
      fail(e.at, "A",
           fmt::format("A = {}: anvil's Gruneisen coefficient is GAMA0 at every "
                       "compression; the volume correction A must be 0",
                       e.a));
    if (e.e0 != 0)
      fail(e.at, "E0",
           fmt::format("E0 = {}: anvil's particles start with no internal energy; "
                       "E0 must be 0",
                       e.e0));
    if (e.v0 != 0 && e.v0 != 1)
      fail(e.at2, "V0",
           fmt::format("V0 = {}: anvil's particles start at their material's "
                       "density (V0 = 1)",
                       e.v0));
    if (e.lcid != 0)
      fail(e.at2, "LCID",
           fmt::format("LCID {}: an energy deposition curve is not supported", e.lcid));
    return {{"c0", e.c}, {"s", e.s1}, {"gamma0", e.gamma0}};
  }

  HourglassControl hourglass_of(std::int64_t ihq, double qm) const {
    HourglassControl h;
    // IHQ 1-3: viscous forms; 4, 5, 7 (7 with exact volume integration) and 8 (a shell
    // form): Flanagan-Belytschko stiffness forms; 6: Belytschko-Bindeman's assumed-strain
    // physical stabilisation, QM a scale on the physical stiffness (QM = 1 the full
    // stiffness); 9 and 10 (Puso's and the Cosserat point element's physical forms): the
    // assumed-strain form. 7-10 are replaced with a warning.
    h.model = (ihq == 6 || ihq >= 9) ? HourglassControl::Model::assumed_strain
              : ihq >= 4             ? HourglassControl::Model::stiffness
                                     : HourglassControl::Model::viscous;
    h.coefficient = qm > 0 ? qm : 0.1; // LS-DYNA's default QM
    return h;
  }

  bool mesh_only_;
  std::string title_;
  std::vector<Vec3> nodes_;
  std::vector<Where> node_at_;
  std::vector<std::int64_t> node_ids_;
  std::unordered_map<std::int64_t, std::int64_t> node_index_;
  struct NodeTc { // a *NODE card's TC constraint
    std::int64_t nid;
    int tc;
    Where at;
    std::int64_t seq;
  };
  std::vector<NodeTc> node_tc_;
  std::int64_t card_seq_ = 0; // constraint and motion cards so far (their order)
  std::vector<RawElement> elements_;
  std::unordered_map<std::int64_t, std::size_t> element_index_;
  std::vector<PartCard> parts_;
  std::map<std::int64_t, SectionCard> sections_, other_sections_;
  std::map<std::int64_t, SphSectionCard> sph_sections_;
  std::vector<RawSph> sph_elements_;
  std::vector<std::string> sph_notes_;         // what anvil does otherwise with particles
  std::vector<std::string> sph_control_notes_; // those of the *CONTROL_SPH in force
  std::optional<Where> control_sph_at_;
  bool sph_corrected_ = false; // *CONTROL_SPH FORM 1: the renormalised gradient
  std::map<std::int64_t, MaterialCard> materials_;
  std::map<std::int64_t, EosCard> eos_;
  std::map<std::int64_t, HourglassCard> hourglass_;
  std::map<std::int64_t, IdSet> node_sets_, part_sets_;
  std::vector<Spc> spcs_;
  std::vector<MotionCard> motions_;
  std::vector<BodyCard> bodies_;
  std::vector<NodeLoadCard> node_loads_;
  std::vector<SegmentLoadCard> segment_loads_;
  std::map<std::int64_t, SegmentSet> segment_sets_;
  std::set<std::int64_t> curves_warned_;                  // curves said to end before ENDTIM
  std::vector<const Block*> curve_blocks_;                // *DEFINE_CURVE, read by curve()
  std::multimap<std::int64_t, const Block*> curve_index_; // by LCID (0: none readable)
  std::map<std::int64_t, CurveCard> curves_;              // those read
  std::vector<VelocityGen> velocities_;
  std::vector<ContactCard> contacts_;
  std::vector<WallCard> walls_;
  double slsfac_ = 0;
  double rwpnal_ = 0; // *CONTROL_CONTACT: LS-DYNA's planar walls take rigid bodies when > 0
  bool have_termination_ = false;
  Where termination_at_;
  double endtim_ = 0;
  std::int64_t endcyc_ = 0;
  double tssfac_ = 0.9;
  std::int64_t checkpoint_cycles_ = 0; // *DATABASE_BINARY_D3DUMP / RUNRSF CYCL
  // The rigid parts whose *MAT_RIGID holds them (CMO = 1): part name -> CON1, CON2.
  struct RigidConstraint {
    int con1, con2;
    Where at;
  };
  std::map<std::string, RigidConstraint> rigid_constraints_;
  // *CONSTRAINED_RIGID_BODIES: part `merged` joins the body of part `lead`.
  struct RigidMerge {
    std::int64_t lead = 0, merged = 0;
    int iflag = 0;
    Where at;
  };
  std::vector<RigidMerge> rigid_merges_;
  double dtmin_ = 0;              // *CONTROL_TERMINATION DTMIN
  double mass_scaling_dt2ms_ = 0; // |DT2MS| of *CONTROL_TIMESTEP when DT2MS < 0
  SourceLocation mass_scaling_at_;
  std::vector<std::string> timestep_notes_; // the warnings of the *CONTROL_TIMESTEP in force
  std::int64_t control_ihq_ = 0;
  double control_qh_ = 0, control_q1_ = 0, control_q2_ = 0;
  double d3plot_dt_ = 0, history_dt_ = 0;
  bool part_energies_ = false;
  std::int64_t d3plot_states_ = 0;
  struct HistoryNode {
    std::int64_t id; // a node, or a node set
    bool set;
    Where at;
    std::string keyword;
  };
  std::vector<HistoryNode> history_nodes_;
  std::vector<HistoryNode> history_solids_; // elements (`set` unused)
  std::vector<std::string> warnings_;
  std::map<std::string, Unsupported> unsupported_;
};

// Fills in the defaults of the model's optional parameters and checks every value against
// the registry's range (the keyword checks above name LS-DYNA's fields; this is the net
// under them, in anvil's names).
void complete_material(MaterialConfig& m,
                       const std::map<std::string, SourceLocation, std::less<>>& field_of) {
  const MaterialModel* info = find_material_model(m.model);
  if (!info) throw InputError(m.where, fmt::format("no material model '{}'", m.model));
  for (const auto& p : info->params) {
    const std::string name(p.name);
    auto it = m.params.find(name);
    if (it == m.params.end()) {
      if (p.required)
        throw InputError(m.where, fmt::format("{} is missing for anvil's {}", name, m.model));
      m.params[name] = p.default_value;
      continue;
    }
    const double x = it->second;
    const bool low_ok = p.min_exclusive ? x > p.min : x >= p.min;
    const bool high_ok = p.max_exclusive ? x < p.max : x <= p.max;
    if (!low_ok || !high_ok)
      throw InputError(m.where,
                       fmt::format("{} = {} is outside the range of anvil's {}", name, x, m.model));
  }
  if (info->check)
    if (const ParamProblem problem = info->check(m.params, m.tables); !problem.why.empty()) {
      const auto field = field_of.find(problem.key);
      SourceLocation at = field != field_of.end() ? field->second : m.where;
      // A table read from numbered fields (ES1, ES2, ...): the point's own field.
      if (const auto points = field_of.find(problem.key + "[]");
          problem.point >= 0 && points != field_of.end())
        at = {points->second.file, points->second.line,
              points->second.key + std::to_string(problem.point + 1)};
      throw InputError(at, problem.why);
    }
  if (m.params.count("youngs_modulus"))
    if (const std::string why = elastic_wave_problem(m.params); !why.empty())
      throw InputError(m.where, why);
}

Config KeywordReader::config(const std::string& deck_file) {
  Config c;
  c.deck_file = deck_file;
  c.title = title_;
  std::vector<std::string> warnings = std::move(warnings_);

  // Termination.
  if (!have_termination_ || (endtim_ == 0 && endcyc_ == 0))
    throw InputError(
        {deck_file, have_termination_ ? termination_at_.line : 0, "*CONTROL_TERMINATION"},
        "no end: give *CONTROL_TERMINATION with ENDTIM (or ENDCYC)");
  if (endtim_ > 0) c.end_time = endtim_;
  if (endcyc_ > 0) c.end_cycles = endcyc_;
  c.time_step_scale = tssfac_;
  c.checkpoint_every_cycles = checkpoint_cycles_;
  c.time_step_minimum_fraction = dtmin_;
  c.mass_scaling_step = tssfac_ * mass_scaling_dt2ms_;
  c.mass_scaling_where = mass_scaling_at_;
  warnings.insert(warnings.end(), timestep_notes_.begin(), timestep_notes_.end());

  // Parts with solid elements (`order`) and parts of SPH particles (`sph_order`); the
  // others (shells, beams, ...) are left out.
  std::set<std::int64_t> solids, particles;
  for (const auto& e : elements_) solids.insert(e.pid);
  for (const auto& e : sph_elements_) particles.insert(e.pid);
  std::set<std::int64_t> kept;
  std::vector<std::int64_t> order, sph_order;
  for (const auto& p : parts_) {
    const bool has_solids = solids.count(p.pid) > 0, has_particles = particles.count(p.pid) > 0;
    if (has_solids && has_particles)
      throw InputError(p.at.loc("*PART.PID"),
                       fmt::format("part {} has both solid elements and SPH particles "
                                   "(*ELEMENT_SPH): give the particles a part of their own",
                                   p.pid));
    if (!has_solids && !has_particles) {
      warnings.push_back(fmt::format("{}: part {}{} has no *ELEMENT_SOLID elements or "
                                     "*ELEMENT_SPH particles and is left out (anvil models "
                                     "solid hexahedra and SPH particles only)",
                                     p.at.str(), p.pid,
                                     p.heading.empty() ? "" : " (" + shown(p.heading) + ")"));
      continue;
    }
    kept.insert(p.pid);
    (has_solids ? order : sph_order).push_back(p.pid);
  }
  if (order.empty() && sph_order.empty())
    throw InputError({deck_file, 0, "*PART"},
                     "no part has solid elements or SPH particles: anvil needs *PART and "
                     "*ELEMENT_SOLID (or *ELEMENT_SPH) cards");
  Mesh mesh = build_mesh(order, true); // shared by the parts once complete (below)

  // Materials, in order of first use; hourglass and bulk viscosity per part. A
  // *MAT_JOHNSON_COOK with G alone takes its bulk modulus from each part's own EOS, so
  // parts that share it with different EOS get a material each (`mat<MID>_eos<EOSID>`).
  std::map<std::int64_t, std::set<std::int64_t>> eos_of_material; // G-only MID -> EOSIDs
  for (const auto pid : order) {
    const PartCard& p = *std::find_if(parts_.begin(), parts_.end(),
                                      [&](const PartCard& q) { return q.pid == pid; });
    if (const auto m = materials_.find(p.mid);
        m != materials_.end() && m->second.params.count("shear_modulus_only"))
      eos_of_material[p.mid].insert(p.eosid);
  }
  std::set<std::string> material_names;
  std::set<std::int64_t> material_notes_given;
  const std::string part_key = "*PART";
  // The material of part p (its name; added to c.materials at its first use): for its
  // elements, or for its particles, which take the part's *EOS_GRUNEISEN as their
  // equation of state (the hexahedra do not track the specific internal energy).
  auto part_material = [&](const PartCard& p, bool particles) -> std::string {
    const auto mat = materials_.find(p.mid);
    if (mat == materials_.end())
      throw InputError(p.at.loc("*PART.MID"),
                       fmt::format("part {}: material {} is not defined", p.pid, p.mid));
    const MaterialCard& mc = mat->second;
    if (mc.model.empty())
      throw InputError(p.at.loc("*PART.MID"),
                       fmt::format("part {}: material {} is a *{} (at {}), which anvil does not "
                                   "have (supported: *MAT_ELASTIC, *MAT_PLASTIC_KINEMATIC, "
                                   "*MAT_PIECEWISE_LINEAR_PLASTICITY, *MAT_JOHNSON_COOK, "
                                   "*MAT_SIMPLIFIED_JOHNSON_COOK, *MAT_RIGID; *MAT_NULL for "
                                   "particles)",
                                   p.pid, p.mid, mc.keyword, mc.at.str()));
    std::string mname = fmt::format("mat{}", p.mid);
    if (mc.model == "fluid" && !particles)
      throw InputError(p.at.loc("*PART.MID"),
                       fmt::format("part {} has solid elements and material {} is a *{} (at "
                                   "{}): anvil models fluids with SPH particles only "
                                   "(*ELEMENT_SPH)",
                                   p.pid, p.mid, mc.keyword, mc.at.str()));
    if (particles && mc.rigid)
      throw InputError(p.at.loc("*PART.MID"),
                       fmt::format("part {}: SPH particles cannot be rigid (*{} at {})", p.pid,
                                   mc.keyword, mc.at.str()));
    ParamValues params = mc.params; // this part's copy: its EOS may complete it
    ParamValues eos;                // the particles' Mie-Gruneisen parameters, if any
    const bool g_only = params.count("shear_modulus_only") > 0;
    if (g_only && p.eosid == 0)
      throw InputError(mc.at.loc(fmt::format("*{}.PR", mc.keyword)),
                       fmt::format("material {} gives only the shear modulus G; anvil needs PR "
                                   "(or E) for its bulk modulus, or an *EOS_GRUNEISEN on every "
                                   "part that uses it, but part {} (at {}) has no EOSID",
                                   p.mid, p.pid, p.at.str()));
    // Equation of state: anvil's models carry their own linear elastic pressure.
    if (p.eosid != 0) {
      const auto e = eos_.find(p.eosid);
      if (e == eos_.end())
        throw InputError(
            p.at.loc("*PART.EOSID"),
            fmt::format("part {}: equation of state {} is not defined", p.pid, p.eosid));
      const bool gruneisen = particles && starts_with(e->second.keyword, "EOS_GRUNEISEN");
      if (gruneisen) {
        eos = gruneisen_params(e->second);
        mname = fmt::format("mat{}_gruneisen{}", p.mid, p.eosid);
      }
      if (g_only) {
        // *MAT_JOHNSON_COOK with G only: the EOS's bulk sound speed gives K = rho C^2.
        const double G = params["shear_modulus_only"], rho = params["density"];
        const double K = rho * e->second.c * e->second.c;
        const double nu = (3 * K - 2 * G) / (2 * (3 * K + G));
        if (!(K > 0) || !(nu > -1 && nu < 0.5))
          throw InputError(p.at.loc("*PART.EOSID"),
                           fmt::format("part {}: material {} gives only G; anvil needs PR (or E) "
                                       "on the material card, or an *EOS_GRUNEISEN with a "
                                       "sound speed C, for its bulk modulus",
                                       p.pid, p.mid));
        params.erase("shear_modulus_only");
        params["youngs_modulus"] = 2 * G * (1 + nu);
        params["poissons_ratio"] = nu;
        if (!gruneisen && eos_of_material[p.mid].size() > 1)
          mname += fmt::format("_eos{}", p.eosid);
        if (!gruneisen)
          warnings.push_back(fmt::format(
              "{}: part {}: *{} {} is not modelled; anvil gives material {} (G only) the bulk "
              "modulus rho C^2 = {:.6g} Pa of this EOS's sound speed C and a linear elastic "
              "pressure (S1-S3, GAMA0 and the energy term are ignored)",
              p.at.str(), p.pid, e->second.keyword, p.eosid, p.mid, K));
      } else if (!gruneisen) {
        warnings.push_back(fmt::format(
            "{}: part {}: *{} {} is not supported; anvil computes the pressure of material {} "
            "from its linear elastic bulk modulus (E, PR) instead",
            p.at.str(), p.pid, e->second.keyword, p.eosid, p.mid));
      }
    }
    // *MAT_NULL: the part's *EOS_GRUNEISEN gives the pressure, and K = rho C^2 the sound
    // speed at rest.
    if (params.erase("bulk_from_eos")) {
      if (eos.empty())
        throw InputError(p.at.loc("*PART.EOSID"),
                         fmt::format("part {}: material {} is a *{} (at {}), whose pressure "
                                     "comes from an equation of state: give the part an "
                                     "*EOS_GRUNEISEN (EOSID)",
                                     p.pid, p.mid, mc.keyword, mc.at.str()));
      params["bulk_modulus"] = params["density"] * eos["c0"] * eos["c0"];
    }
    if (material_names.insert(mname).second) {
      MaterialConfig m{mname,
                       mc.model,
                       params,
                       mc.tables,
                       eos.empty() ? "" : "mie_gruneisen",
                       eos,
                       mc.at.loc("*" + mc.keyword)};
      if (mc.lcss > 0) {
        // The hardening curve: plastic strain against yield stress (the curve's abscissae
        // and values, its scale factors and offsets applied).
        if (!curve_defined(mc.lcss) && unsupported_.count("DEFINE_TABLE"))
          throw InputError(mc.field_of.at("hardening_curve"),
                           fmt::format("curve {} is not defined (*DEFINE_CURVE); if it is a "
                                       "*DEFINE_TABLE (curves per strain rate), anvil does not "
                                       "read tables: give one curve, and C and P for the rate",
                                       mc.lcss));
        const CurveCard& cc = curve(mc.lcss, mc.field_of.at("hardening_curve"));
        m.tables["hardening_curve"] = {cc.curve.t, cc.curve.value};
      }
      complete_material(m, mc.field_of);
      if (material_notes_given.insert(p.mid).second) {
        const double rho = m.params["density"];
        if (rho < 10 || rho > 1e5)
          warnings.push_back(
              fmt::format("{}: material {}: density {} looks like it is not in kg/m^3: "
                          "anvil reads keyword decks in SI units (m, kg, s, Pa) "
                          "and converts nothing",
                          mc.at.str(), p.mid, rho));
        for (const auto& n : mc.notes) warnings.push_back(n);
      }
      c.materials.push_back(std::move(m));
    }
    return mname;
  };
  std::set<std::int64_t> not_tetrahedra; // parts with an element of another shape
  for (const auto& e : elements_)
    if (shape_of(e.nodes) != Shape::tetrahedron) not_tetrahedra.insert(e.pid);
  for (std::size_t i = 0; i < order.size(); ++i) {
    const PartCard& p = *std::find_if(parts_.begin(), parts_.end(),
                                      [&](const PartCard& q) { return q.pid == order[i]; });
    PartConfig pc;
    pc.name = part_name(p.pid);
    pc.where = p.at.loc(part_key);
    pc.mesh.kind = MeshConfig::Kind::embedded;
    pc.mesh.embedded_block = i;
    pc.mesh.where = pc.where;

    // Section.
    const auto sec = sections_.find(p.secid);
    if (sec == sections_.end()) {
      if (const auto sph = sph_sections_.find(p.secid); sph != sph_sections_.end())
        throw InputError(p.at.loc("*PART.SECID"),
                         fmt::format("part {} has solid elements but its section {} is a "
                                     "*SECTION_SPH (at {}), not a *SECTION_SOLID",
                                     p.pid, p.secid, sph->second.at.str()));
      const auto other = other_sections_.find(p.secid);
      throw InputError(
          p.at.loc("*PART.SECID"),
          other != other_sections_.end()
              ? fmt::format("part {} has solid elements but its section {} is a *{} "
                            "(at {}), not a *SECTION_SOLID",
                            p.pid, p.secid, other->second.keyword, other->second.at.str())
              : fmt::format("part {}: section {} is not defined (*SECTION_SOLID)", p.pid, p.secid));
    }
    // ELFORM 10 (LS-DYNA's one-point tetrahedron) on tetrahedra is what anvil's element is
    // on a tetrahedron (element.md): no warning.
    const bool tetrahedra = !not_tetrahedra.count(p.pid);
    if (sec->second.elform != 1 && sec->second.elform != 0 &&
        !(sec->second.elform == 10 && tetrahedra))
      warnings.push_back(fmt::format("{}: section {} asks for ELFORM {}; anvil uses its one-point "
                                     "hexahedron with hourglass control (ELFORM 1) for part {}",
                                     sec->second.at.str(), p.secid, sec->second.elform, p.pid));

    const std::string mname = part_material(p, false);
    const MaterialCard& mc = materials_.at(p.mid);
    pc.material = mname;
    pc.rigid = mc.rigid;
    pc.erosion.plastic_strain = mc.failure_strain;
    if (mc.con1 != 0 || mc.con2 != 0) rigid_constraints_[pc.name] = {mc.con1, mc.con2, mc.at};

    // Hourglass and bulk viscosity: the part's *HOURGLASS, else the *CONTROL_ cards, else
    // LS-DYNA's defaults (which are anvil's: viscous 0.1, Q1 1.5, Q2 0.06).
    const HourglassCard hg = hourglass_card_of(p);
    const std::int64_t ihq = hg.ihq;
    const double qm = hg.qm, q1 = hg.q1, q2 = hg.q2;
    if (ihq >= 7)
      warnings.push_back(fmt::format("{}: part {}: hourglass type IHQ {} is replaced by anvil's "
                                     "{} with the same coefficient",
                                     p.at.str(), p.pid, ihq,
                                     ihq >= 9 ? "assumed-strain form (IHQ 6)"
                                              : "Flanagan-Belytschko stiffness form (IHQ 4)"));
    pc.hourglass = hourglass_of(ihq, qm);
    if (q1 > 0) pc.bulk_viscosity.quadratic = q1;
    if (q2 > 0) pc.bulk_viscosity.linear = q2;
    c.parts.push_back(std::move(pc));
  }

  // Particle sets: the parts of *ELEMENT_SPH particles in *PART order, each with its
  // particles in card order, at their nodes (which no solid element may use).
  std::vector<char> in_solid(nodes_.size(), 0);
  for (const auto& e : elements_)
    for (const auto n : e.nodes) in_solid[static_cast<std::size_t>(node_index_.at(n))] = 1;
  std::vector<std::shared_ptr<ParticleList>> lists;
  std::unordered_map<std::int64_t, ParticleAt> particle_of; // node position -> its particle
  particle_sets(c, sph_order, part_material, in_solid, lists, particle_of, warnings);

  auto part_ref = [&](std::int64_t pid, const Where& at, const std::string& key) {
    if (std::none_of(parts_.begin(), parts_.end(), [&](const PartCard& p) { return p.pid == pid; }))
      throw InputError(at.loc(key), fmt::format("part {} is not defined (*PART)", pid));
    return kept.count(pid) > 0;
  };

  // Initial velocities, in deck order (later ones override earlier ones on shared nodes,
  // as in the YAML deck).
  int velocity_groups = 0; // *INITIAL_VELOCITY_NODE's sets velocity_nodes_N
  for (const auto& v : velocities_) {
    const std::string key = "*" + v.keyword;
    std::vector<Selection> targets;
    if (v.styp == 4) {
      Selection s;
      s.name = fmt::format("velocity_nodes_{}", ++velocity_groups);
      std::vector<std::int64_t> positions;
      for (std::size_t i = 0; i < v.nodes.size(); ++i)
        positions.push_back(
            node_position(v.nodes[i], v.node_at[i], key + ".NID", "the initial velocity"));
      std::sort(positions.begin(), positions.end());
      mesh.node_sets[s.name] = std::move(positions);
      s.where = v.at.loc(key);
      targets.push_back(s);
    } else if (v.styp == 3) {
      Selection s;
      s.name = node_set_name(v.id, v.at, key + (v.keyword == "INITIAL_VELOCITY" ? ".NSID" : ".ID"));
      s.where = v.at.loc(key);
      targets.push_back(s);
    } else {
      std::vector<std::string> names;
      if (v.mass_center) {
        // LS-DYNA: "for a rigid body or a nodal rigid body".
        names.push_back(rigid_part(v.id, v.at.loc(key + ".PID"),
                                   key + " sets the velocity of a rigid body (give "
                                         "*INITIAL_VELOCITY_GENERATION for a deformable part)"));
      } else if (v.styp == 2) {
        if (part_ref(v.id, v.at, key + ".ID")) names.push_back(part_name(v.id));
      } else if (v.styp == 1) {
        names = part_set(v.id, v.at, key + ".ID", kept);
      } else {
        for (const auto pid : order) names.push_back(part_name(pid));
        for (const auto pid : sph_order) names.push_back(part_name(pid));
      }
      for (const auto& n : names) {
        Selection s;
        s.part = n;
        s.where = v.at.loc(key);
        targets.push_back(s);
      }
    }
    for (const auto& s : targets) {
      InitialCondition ic;
      ic.nodes = s;
      ic.velocity = v.velocity;
      ic.angular_velocity = v.angular;
      ic.center = v.center;
      ic.about_mass_center = v.mass_center;
      ic.where = v.at.loc(key);
      c.initial_conditions.push_back(ic);
    }
  }

  // Merged rigid bodies: each PIDS joins PIDL's body (its own *MAT_RIGID constraints give
  // way to the body's lead's, as in LS-DYNA).
  for (const RigidMerge& m : rigid_merges_) {
    const SourceLocation at = m.at.loc("*CONSTRAINED_RIGID_BODIES.PIDS");
    const std::string lead = rigid_part(m.lead, m.at.loc("*CONSTRAINED_RIGID_BODIES.PIDL"),
                                        "*CONSTRAINED_RIGID_BODIES merges its body");
    const std::string merged = rigid_part(m.merged, at, "*CONSTRAINED_RIGID_BODIES merges it");
    auto part = std::find_if(c.parts.begin(), c.parts.end(),
                             [&](const PartConfig& p) { return p.name == merged; });
    if (part == c.parts.end()) continue; // (rigid_part() has named it)
    if (!part->merge_with.empty())
      throw InputError(at, fmt::format("part {} is merged twice (into part {} before): a part "
                                       "joins one body",
                                       m.merged, part->merge_with.substr(4)));
    part->merge_with = lead;
    part->merge_where = at;
    if (m.iflag == 1)
      warnings.push_back(fmt::format("{}: IFLAG = 1 (keep PIDL's mass properties) is not "
                                     "supported: anvil's merged body has the mass and inertia "
                                     "of all its parts' nodes",
                                     m.at.str()));
    if (const auto con = rigid_constraints_.find(merged); con != rigid_constraints_.end()) {
      warnings.push_back(fmt::format("{}: the *MAT_RIGID constraints of part {} (CMO) are "
                                     "ignored: it is merged into the body of part {} ({}), "
                                     "whose constraints hold the body",
                                     con->second.at.str(), m.merged, m.lead, m.at.str()));
      rigid_constraints_.erase(con);
    }
  }
  check_rigid_merges(c.parts);
  conditions(c, mesh, warnings);
  loads(c, mesh, warnings);
  // A node set's particles go to their particle list (conditions on the set act on them
  // too); its other nodes stay.
  if (!particle_of.empty())
    for (auto& [name, positions] : mesh.node_sets) {
      std::vector<std::int64_t> nodes;
      for (const auto pos : positions) {
        const auto it = particle_of.find(pos);
        if (it == particle_of.end())
          nodes.push_back(pos);
        else
          lists[it->second.set]->sets[name].push_back(it->second.index);
      }
      positions = std::move(nodes);
    }
  for (auto& list : lists)
    for (auto& [name, members] : list->sets) std::sort(members.begin(), members.end());

  const auto shared = std::make_shared<const Mesh>(std::move(mesh));
  for (auto& pc : c.parts) pc.mesh.embedded = shared;

  // Contact: every *CONTACT_ card becomes anvil's general contact among its parts (both
  // sides of a two-surface form), and several cards one contact among all their parts.
  std::optional<ContactConfig> merged;
  for (const auto& k : contacts_) {
    ContactConfig cc;
    cc.where = k.at.loc("*" + k.keyword);
    bool all = false;
    auto side = [&](std::int64_t id, std::int64_t type, const char* field) {
      if (id == 0) {
        all = true;
        return;
      }
      const std::string key = "*" + k.keyword + "." + field;
      std::vector<std::string> parts;
      if (type == 3) {
        if (part_ref(id, k.at, key)) parts.push_back(part_name(id));
      } else {
        parts = part_set(id, k.at, key, kept);
      }
      if (parts.empty())
        throw InputError(k.at.loc(key), fmt::format("the contact's {} side has no part with "
                                                    "solid elements or particles",
                                                    field[0] == 'S' ? "slave" : "master"));
      for (auto& p : parts)
        if (std::find(cc.parts.begin(), cc.parts.end(), p) == cc.parts.end()) cc.parts.push_back(p);
    };
    side(k.ssid, k.sstyp, "SSID");
    if (k.two_surface) side(k.msid, k.mstyp, "MSID");
    if (all) cc.parts.clear();
    if (k.two_surface)
      warnings.push_back(fmt::format(
          "{}: *{} is anvil's general contact among the parts of both sides ({}): symmetric "
          "node-to-face contact, and contact within a side and self-contact are included",
          k.at.str(), k.keyword, all ? "all parts" : fmt::format("{}", fmt::join(cc.parts, ", "))));
    cc.friction = k.fs;
    // LS-DYNA's penalty stiffness for solid segments is SLSFAC * SFS * K A^2 / V, anvil's
    // penalty_scale * K A^2 / V. Two sides with their own scales (SFS, SFM): the slave's.
    cc.penalty_scale = (slsfac_ > 0 ? slsfac_ : 0.1) * k.sfs;
    if (!std::isfinite(cc.penalty_scale))
      throw InputError(k.at.loc("*" + k.keyword + ".SFS"),
                       fmt::format("the penalty scale SLSFAC x SFS = {} x {} is not a finite "
                                   "number",
                                   slsfac_ > 0 ? slsfac_ : 0.1, k.sfs));
    if (k.two_surface && k.sfm != k.sfs)
      warnings.push_back(fmt::format("{}: contact penalty scales SFS = {} and SFM = {}: anvil's "
                                     "contact is symmetric and uses SFS on both sides",
                                     k.at.str(), k.sfs, k.sfm));
    if (k.dc > 0 && k.fd != k.fs)
      warnings.push_back(fmt::format("{}: contact friction: anvil uses the static coefficient "
                                     "FS = {} throughout (FD and DC are ignored)",
                                     k.at.str(), k.fs));
    if (k.vdc != 0)
      warnings.push_back(fmt::format("{}: contact viscous damping VDC is ignored", k.at.str()));
    if (k.bt != 0 || (k.dt != 0 && k.dt < 1e19))
      warnings.push_back(fmt::format("{}: contact birth and death times (BT, DT) are ignored: "
                                     "the contact is active throughout",
                                     k.at.str()));
    if (!merged) {
      merged = std::move(cc);
      continue;
    }
    // anvil has one contact, with one friction coefficient and one penalty scale.
    const ContactCard& first = contacts_.front();
    if (cc.friction != merged->friction)
      throw InputError(k.at.loc("*" + k.keyword + ".FS"),
                       fmt::format("friction FS = {} differs from FS = {} of the contact at {}: "
                                   "anvil's contacts are one general contact with one friction "
                                   "coefficient (give every *CONTACT_ card the same FS)",
                                   cc.friction, merged->friction, first.at.str()));
    if (cc.penalty_scale != merged->penalty_scale)
      throw InputError(k.at.loc("*" + k.keyword + ".SFS"),
                       fmt::format("penalty scale SFS = {} differs from SFS = {} of the contact "
                                   "at {}: anvil's contacts are one general contact with one "
                                   "penalty scale",
                                   k.sfs, first.sfs, first.at.str()));
    if (merged->parts.empty() || cc.parts.empty())
      merged->parts.clear();
    else
      for (auto& p : cc.parts)
        if (std::find(merged->parts.begin(), merged->parts.end(), p) == merged->parts.end())
          merged->parts.push_back(p);
  }
  if (merged) {
    if (contacts_.size() > 1)
      warnings.push_back(fmt::format(
          "{}: the {} *CONTACT_ definitions are one general contact among {}: parts of "
          "different definitions meet too where they touch",
          contacts_.front().at.str(), contacts_.size(),
          merged->parts.empty() ? "all parts"
                                : fmt::format("parts {}", fmt::join(merged->parts, ", "))));
    c.contact.push_back(std::move(*merged));
  }

  // Rigid walls: a plane through the tail with the normal towards the head. anvil's stop
  // rigid bodies, LS-DYNA's only with RWPNAL > 0 (QA round 37: the answer changed unsaid).
  if (!walls_.empty() && !(rwpnal_ > 0)) {
    std::vector<std::string> rigid;
    for (const auto& p : c.parts)
      if (p.rigid) rigid.push_back(p.name);
    if (!rigid.empty())
      warnings.push_back(fmt::format(
          "{}: anvil's planar rigid walls stop rigid bodies ({}), kinematically; LS-DYNA's "
          "leave them out unless *CONTROL_CONTACT RWPNAL > 0 (here {}), so there they would "
          "pass through",
          walls_.front().at.str(), fmt::join(rigid, ", "), rwpnal_));
  }
  for (const auto& w : walls_) {
    RigidWallConfig rw;
    rw.where = w.at.loc("*RIGIDWALL_PLANAR");
    rw.point = w.tail;
    const Vec3 n = w.head - w.tail;
    rw.normal = n * (1 / norm(n));
    rw.friction = w.fric;
    if (w.nsid != 0 || w.nsidex != 0 || w.boxid != 0)
      warnings.push_back(fmt::format("{}: rigid wall: NSID, NSIDEX and BOXID are ignored: "
                                     "anvil's walls act on every node",
                                     w.at.str()));
    if (w.fric >= 1)
      warnings.push_back(fmt::format("{}: rigid wall: FRIC = {} (no sliding) is taken as a "
                                     "Coulomb coefficient of {}",
                                     w.at.str(), w.fric, w.fric));
    if (w.offset != 0 || w.birth != 0 || (w.death != 0 && w.death < 1e19) || w.wvel != 0)
      warnings.push_back(fmt::format("{}: rigid wall: OFFSET, BIRTH, DEATH and WVEL are "
                                     "ignored",
                                     w.at.str()));
    c.rigid_walls.push_back(rw);
  }

  // Output intervals.
  if (d3plot_states_ > 0 && endtim_ > 0)
    c.fields_every = endtim_ / static_cast<double>(d3plot_states_);
  else
    c.fields_every = d3plot_dt_;
  c.history_every = history_dt_;
  c.part_energies = part_energies_;

  // Probes: *DATABASE_HISTORY_NODE (and _ID, _SET), at the node's position. anvil probes
  // the model's node nearest to a point, the lowest id among coincident ones; a node that
  // no element uses is in no rank's model, so a probe there would follow another node.
  std::vector<char> used = in_solid; // and the particles' nodes
  for (const auto& [pos, particle] : particle_of) used[static_cast<std::size_t>(pos)] = 1;
  std::set<std::int64_t> probed;
  std::map<std::array<double, 3>, std::int64_t> first_at; // position -> first node there
  if (!history_nodes_.empty())
    for (std::size_t j = 0; j < nodes_.size(); ++j)
      if (used[j])
        first_at.emplace(std::array<double, 3>{nodes_[j].x, nodes_[j].y, nodes_[j].z},
                         static_cast<std::int64_t>(j));
  auto probe = [&](std::int64_t pos, const HistoryNode& h) {
    const std::int64_t nid = node_ids_[static_cast<std::size_t>(pos)];
    if (!probed.insert(nid).second) return;
    const Vec3 x = nodes_[static_cast<std::size_t>(pos)];
    const std::int64_t j = first_at.at({x.x, x.y, x.z});
    if (j != pos)
      warnings.push_back(fmt::format("{}: history node {} lies on node {} (same coordinates); "
                                     "the probe follows node {}",
                                     h.at.str(), nid, node_ids_[j], node_ids_[j]));
    c.probes.push_back(ProbeConfig{fmt::format("node{}", nid), x, h.at.loc(h.keyword)});
  };
  for (const auto& h : history_nodes_) {
    if (!h.set) {
      const auto pos = node_position(h.id, h.at, h.keyword + ".ID", "the history node list");
      if (!used[static_cast<std::size_t>(pos)])
        throw InputError(h.at.loc(h.keyword + ".ID"),
                         fmt::format("history node {} belongs to no solid element or particle: "
                                     "anvil's model holds only the nodes of its elements, so "
                                     "nothing there can be recorded",
                                     h.id));
      probe(pos, h);
      continue;
    }
    // A set's nodes that no element uses (a left-out shell part's) are skipped, said once.
    const auto it = node_sets_.find(h.id);
    if (it == node_sets_.end())
      throw InputError(h.at.loc(h.keyword + ".ID"),
                       fmt::format("node set {} is not defined (*SET_NODE_LIST)", h.id));
    std::vector<std::int64_t> unused;
    for (const auto pos : resolve_node_set(h.id, it->second)) {
      if (used[static_cast<std::size_t>(pos)])
        probe(pos, h);
      else
        unused.push_back(node_ids_[static_cast<std::size_t>(pos)]);
    }
    if (!unused.empty())
      warnings.push_back(fmt::format("{}: {} node{} of history node set {} (node {}{}) belong "
                                     "to no solid element or particle and get no probe",
                                     h.at.str(), unused.size(), unused.size() == 1 ? "" : "s", h.id,
                                     unused.front(), unused.size() > 1 ? ", ..." : ""));
  }

  // Element probes: *DATABASE_HISTORY_SOLID (and _ID), the element by its id (at its
  // centroid, the mean of its corners, for the outside-the-model check). By the centroid
  // alone, a coincident element could stand in for it (QA round 28).
  if (!history_solids_.empty()) {
    auto centroid = [&](const RawElement& e) {
      Vec3 x{0, 0, 0};
      for (const auto n : e.nodes) x = x + nodes_[static_cast<std::size_t>(node_index_.at(n))];
      return x * 0.125;
    };
    std::set<std::int64_t> probed;
    for (const auto& h : history_solids_) {
      const auto it = element_index_.find(h.id);
      if (it == element_index_.end())
        throw InputError(h.at.loc(h.keyword + ".ID"),
                         fmt::format("history element {} is not a solid element "
                                     "(*ELEMENT_SOLID)",
                                     h.id));
      if (!probed.insert(h.id).second) continue;
      c.element_probes.push_back(ProbeConfig{fmt::format("solid{}", h.id),
                                             centroid(elements_[it->second]), h.at.loc(h.keyword),
                                             h.id});
    }
  }

  // One warning lists every keyword anvil ignored.
  if (std::string w = ignored_keywords(deck_file); !w.empty()) warnings.push_back(std::move(w));
  c.warnings = std::move(warnings);
  return c;
}

std::string KeywordReader::ignored_keywords(const std::string& deck_file) const {
  if (unsupported_.empty()) return "";
  std::string list;
  for (const auto& [name, u] : unsupported_)
    list += fmt::format("{}*{} ({}x, first at {})", list.empty() ? "" : ", ", name, u.count,
                        u.first.str());
  return fmt::format("{}: {} keyword{} not supported by anvil and ignored: {}", deck_file,
                     unsupported_.size(), unsupported_.size() == 1 ? " is" : "s are", list);
}

InputError KeywordReader::with_ignored_keywords(const InputError& e,
                                                const std::string& deck_file) const {
  const std::string w = ignored_keywords(deck_file);
  if (w.empty()) return e;
  // The warning goes on a line of its own after the error, as `anvil` prints warnings:
  // an ignored keyword (a *PART_COMPOSITE) is often the cause of the error (its part "not
  // defined"), and the warning is otherwise lost with the Config.
  const std::string what = e.what(), prefix = e.where().str() + ": ";
  const std::string note = "\nanvil: warning: " + w;
  if (starts_with(what, prefix)) return InputError(e.where(), what.substr(prefix.size()) + note);
  return InputError(what + note);
}

// Runs `f`, turning allocation failures on absurd input into an InputError.
template <class F>
auto guarded(const std::string& name, F&& f) {
  try {
    return f();
  } catch (const std::bad_alloc&) {
    throw InputError(SourceLocation{name, 0, ""}, "the deck does not fit in memory");
  } catch (const std::length_error&) {
    throw InputError(SourceLocation{name, 0, ""}, "the deck does not fit in memory");
  } catch (const fs::filesystem_error& e) {
    throw InputError(SourceLocation{name, 0, ""}, e.what());
  }
}

// No size limit: a keyword deck may hold its mesh.
std::string slurp(const std::string& path) {
  return read_input_file(path, std::numeric_limits<std::uintmax_t>::max());
}

std::string dir_of(const std::string& path) {
  const auto d = fs::path(path).parent_path();
  return d.empty() ? "." : d.string();
}

} // namespace

bool is_keyword_file(const std::string& path) {
  const std::string ext = upper(fs::path(path).extension().string());
  return ext == ".K" || ext == ".KEY" || ext == ".DYN";
}

Config parse_keyword_deck(std::string_view text, const std::string& name,
                          const std::string& base_dir) {
  return guarded(name, [&] {
    Lexer lex(true);
    lex.lex_main(text, name, base_dir);
    KeywordReader r(false);
    try {
      r.read(lex.blocks());
      return r.config(name);
    } catch (const InputError& e) {
      throw r.with_ignored_keywords(e, name);
    }
  });
}

Config read_keyword_deck(const std::string& path) {
  const std::string text = guarded(path, [&] { return slurp(path); });
  return parse_keyword_deck(text, path, dir_of(path));
}

Mesh parse_keyword_mesh(std::string_view text, const std::string& name,
                        const std::string& base_dir) {
  return guarded(name, [&] {
    Lexer lex(false);
    lex.lex_main(text, name, base_dir);
    KeywordReader r(true);
    r.read(lex.blocks());
    return r.mesh();
  });
}

Mesh read_keyword_mesh(const std::string& path) {
  const std::string text = guarded(path, [&] { return slurp(path); });
  return parse_keyword_mesh(text, path, dir_of(path));
}

} // namespace anvil
