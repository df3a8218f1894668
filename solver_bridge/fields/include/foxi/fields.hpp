// foxi/fields.hpp: the field importer (foxi::fields), in one include. The entry points, one a line
// (declared in the topic headers below, which say more):
//
//   read_field_source(path)                   a file's fields and what they stand on (field_source.hpp)
//   read_frd, parse_frd, read_field_csv,       the readers by format (field_source.hpp)
//     parse_field_csv, read_pvd
//   transfer_fields(source, mesh, params)     the fields carried onto a mesh by id or by location
//                                             (transfer.hpp)
//   FieldError                                why a transfer was refused (field_source.hpp)
#pragma once

#include "foxi/fields/field_source.hpp"
#include "foxi/fields/transfer.hpp"
