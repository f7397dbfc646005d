#include "scoleid/io/mat_file.h"

#include <unistd.h>

#include <filesystem>
#include <stdexcept>

#include "scoleid/io/error.h"

#ifdef SCOLEID_HAVE_MATIO
#include <matio.h>
#endif

namespace scoleid::io {

#ifdef SCOLEID_HAVE_MATIO

bool mat_files_supported() { return true; }

namespace {

matvar_t* matrix_var(const MatVariable& v) {
  if (v.values.size() != v.rows * v.cols) throw std::invalid_argument("mat variable '" + v.name + "': size mismatch");
  std::size_t dims[2] = {v.rows, v.cols};
  return Mat_VarCreate(v.name.c_str(), MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, const_cast<double*>(v.values.data()), 0);
}

matvar_t* strings_var(const MatVariable& v) {
  std::size_t dims[2] = {v.strings.size(), 1};
  matvar_t* cell = Mat_VarCreate(v.name.c_str(), MAT_C_CELL, MAT_T_CELL, 2, dims, nullptr, 0);
  for (std::size_t i = 0; cell && i < v.strings.size(); ++i) {
    std::size_t sd[2] = {1, v.strings[i].size()};
    matvar_t* s = Mat_VarCreate(nullptr, MAT_C_CHAR, MAT_T_UINT8, 2, sd, const_cast<char*>(v.strings[i].data()), 0);
    Mat_VarSetCell(cell, static_cast<int>(i), s);
  }
  return cell;
}

}  // namespace

void write_mat_file(const std::string& path, const std::vector<MatVariable>& variables) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path tmp = target.parent_path() / (target.filename().string() + ".tmp." + std::to_string(::getpid()));
  mat_t* mat = Mat_CreateVer(tmp.c_str(), "scoleid", MAT_FT_MAT5);
  if (!mat) throw std::runtime_error("cannot write '" + tmp.string() + "'");
  bool ok = true;
  for (const auto& v : variables) {
    matvar_t* var = v.is_strings ? strings_var(v) : matrix_var(v);
    ok = ok && var && Mat_VarWrite(mat, var, MAT_COMPRESSION_NONE) == 0;
    if (var) Mat_VarFree(var);
  }
  Mat_Close(mat);
  std::error_code ec;
  if (ok) fs::rename(tmp, target, ec);
  if (!ok || ec) {
    fs::remove(tmp, ec);
    throw std::runtime_error("cannot write '" + path + "'");
  }
}

#else

bool mat_files_supported() { return false; }

void write_mat_file(const std::string& path, const std::vector<MatVariable>&) {
  throw InputError("'" + path + "': this build writes no .mat files (libmatio was not found when it was configured; write .json)");
}

#endif

}  // namespace scoleid::io
