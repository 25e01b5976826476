// LS-DYNA keyword decks (.k, .key, .dyn) as input: the subset of keywords an explicit
// solid-dynamics model of hexahedra needs, read into the same typed Config the YAML deck
// reader produces (docs/keyword.md lists the keywords, fields and their mapping). The
// deck is taken to be in consistent SI units; nothing is scaled.
//
// Both card formats are read: fixed columns (LS-DYNA's 8/10/16-character fields, the long
// format with 20-character fields from `*KEYWORD LONG=Y` or a keyword's `+` suffix, and
// the I10 format from `I10=Y` or `%`) and comma-separated free format. Every problem is an
// InputError naming the file, the line and the keyword and field (`*NODE.X`); keywords
// anvil does not support are collected into one warning in Config::warnings.
#pragma once

#include <string>
#include <string_view>

#include "anvil/io/config.hpp"
#include "anvil/mesh/mesh.hpp"

namespace anvil {

// Whether `path` names a keyword deck by its extension (.k, .key, .dyn, any case).
bool is_keyword_file(const std::string& path);

// Reads the keyword deck at `path` and the files it *INCLUDEs (relative to the including
// file). The mesh travels in the Config as one embedded Mesh shared by the parts (one
// block per *PART with solid elements, in *PART order).
Config read_keyword_deck(const std::string& path);

// The same from text: `name` stands for the file in messages, `base_dir` resolves its
// *INCLUDEs. Never throws anything but InputError, whatever the text (fuzzing entry point).
Config parse_keyword_deck(std::string_view text, const std::string& name,
                          const std::string& base_dir = ".");

// Only the mesh of a keyword file, for `mesh: {file: model.k}` in a YAML deck: *NODE,
// *ELEMENT_SOLID (one block per part, in *PART order, then parts without a *PART card in
// order of first use), *SET_NODE_LIST sets as `nodeset_<SID>`; *INCLUDE is followed and
// every other keyword is ignored. Nodes keep the file's order.
Mesh read_keyword_mesh(const std::string& path);
Mesh parse_keyword_mesh(std::string_view text, const std::string& name,
                        const std::string& base_dir = ".");

} // namespace anvil
