#include "continuum/output.hpp"

#include <fmt/format.h>

#include <cstdint>
#include <string>
#include <utility>

#include "common/atomic_output.hpp"
#include "common/hdf5_file.hpp"
#include "common/run_file.hpp"

namespace shaker::continuum {

BoxView view_of(const TimeIntegrator& solver) {
  return BoxView{solver.op().grid(), solver.state(),
                 RunScalars{solver.time(), solver.op().settings().e, solver.budget(), solver.counters()}};
}

double total_energy(const BoxView& box) {
  const Grid& g = box.grid;
  return interior_energy_sum(g, box.state) * g.h / (static_cast<double>(g.nx) * g.ny);
}

Profile horizontal_profile(const BoxView& box, const ShakerKinematics& shaker) {
  const Grid& g = box.grid;
  const State& s = box.state;
  const double t = box.scalars.time;
  Profile p;
  p.time = t;
  p.phase = shaker.phase(t);
  p.plate_z = shaker.position(t);
  p.plate_v = shaker.velocity(t);
  p.bin_height = g.h;
  const double columns = static_cast<double>(g.nx) * g.ny;
  for (int k = 0; k < g.nz; ++k) {
    double n = 0, momentum = 0, thermal = 0;
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const auto c = g.index(i, j, k);
        const Primitive w = to_primitive(s, c);
        n += w.n;
        momentum += s.q[momentum_z][c];
        thermal += w.n * w.T;
      }
    // Mass-weighted horizontal means: the same pooling as the MD bins.
    p.z.push_back(g.center(k) + p.plate_z);
    p.n.push_back(n / columns);
    p.nu.push_back(volume_fraction(n / columns));
    p.uz.push_back(momentum / n + p.plate_v);
    p.T.push_back(thermal / n);
  }
  return p;
}

Diagnostics diagnostics(const BoxView& box, const ShakerKinematics& shaker) {
  const Grid& g = box.grid;
  const State& s = box.state;
  const double t = box.scalars.time;
  const double plate_z = shaker.position(t), plate_v = shaker.velocity(t);
  const double area_weight = g.dimension == 3 ? g.h * g.h * g.h / (g.nx * g.h * g.ny * g.h) : g.h;
  const double e = box.scalars.e;
  Diagnostics d;
  double moment = 0;
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const auto c = g.index(i, j, k);
        const Primitive w = to_primitive(s, c);
        const double z = g.center(k) + plate_z, uz = w.uz + plate_v;
        d.mass += w.n * area_weight;
        moment += w.n * z * area_weight;
        d.kinetic += 0.5 * w.n * (w.ux * w.ux + w.uy * w.uy + uz * uz) * area_weight;
        d.thermal += 1.5 * w.n * w.T * area_weight;
        d.potential += w.n * gravity * z * area_weight;
        d.loss_rate += model::collisional_loss(w.n, std::max(w.T, 0.0), e) * area_weight;
      }
  d.center_of_mass = moment / d.mass;
  return d;
}

FieldSnapshot snapshot(const BoxView& box, const ShakerKinematics& shaker, std::int64_t cycle) {
  const Grid& g = box.grid;
  FieldSnapshot f;
  f.cycle = cycle;
  f.time = box.scalars.time;
  f.phase = shaker.phase(f.time);
  f.plate_z = shaker.position(f.time);
  f.plate_v = shaker.velocity(f.time);
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const Primitive w = to_primitive(box.state, g.index(i, j, k));
        f.n.push_back(w.n);
        f.nu.push_back(volume_fraction(w.n));
        f.ux.push_back(w.ux);
        f.uy.push_back(w.uy);
        f.uz.push_back(w.uz + f.plate_v);
        f.T.push_back(w.T);
      }
  return f;
}

namespace {

// The XDMF describes the box as an unstructured grid of hexahedra, not as a 3DCoRectMesh:
// meshio reads only unstructured topologies with XYZ geometry, and the corners of an
// unstructured grid can carry each snapshot's plate position.

/// Index of corner (i, j, k), x fastest: (nx + 1) (ny + 1) (nz + 1) corners.
std::int64_t corner(const Grid& g, int i, int j, int k) {
  return (static_cast<std::int64_t>(k) * (g.ny + 1) + j) * (g.nx + 1) + i;
}

/// The corners of each cell in VTK/XDMF hexahedron order (the bottom face anticlockwise seen
/// from above, then the top face), cells in the order of the field arrays.
std::vector<std::int64_t> hexahedra(const Grid& g) {
  constexpr std::pair<int, int> face[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  std::vector<std::int64_t> cells;
  cells.reserve(8 * g.interior_cells());
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i)
        for (int dk = 0; dk < 2; ++dk)
          for (const auto& [di, dj] : face)
            cells.push_back(corner(g, i + di, j + dj, k + dk));
  return cells;
}

/// Lab-frame corner coordinates (x, y, z) of the grid when the plate is at plate_z.
std::vector<double> corners(const Grid& g, double plate_z) {
  std::vector<double> xyz;
  xyz.reserve(3 * static_cast<std::size_t>(g.nx + 1) * (g.ny + 1) * (g.nz + 1));
  for (int k = 0; k <= g.nz; ++k)
    for (int j = 0; j <= g.ny; ++j)
      for (int i = 0; i <= g.nx; ++i) {
        xyz.push_back(i * g.h);
        xyz.push_back(j * g.h);
        xyz.push_back(k * g.h + plate_z);
      }
  return xyz;
}

std::string hdf_item(const std::string& dimensions, const char* number_type,
                     const std::string& file, const std::string& dataset) {
  return fmt::format("<DataItem Dimensions=\"{}\" NumberType=\"{}\" Precision=\"8\" "
                     "Format=\"HDF\">{}:/{}</DataItem>\n",
                     dimensions, number_type, file, dataset);
}

struct FieldColumn {
  const char* name;
  std::vector<double> FieldSnapshot::*values;
  const char* units;
};
constexpr FieldColumn field_columns[] = {{"n", &FieldSnapshot::n, "1/sigma^3"},
                                         {"nu", &FieldSnapshot::nu, "1"},
                                         {"ux", &FieldSnapshot::ux, "sqrt(g sigma)"},
                                         {"uy", &FieldSnapshot::uy, "sqrt(g sigma)"},
                                         {"uz", &FieldSnapshot::uz, "sqrt(g sigma)"},
                                         {"T", &FieldSnapshot::T, "g sigma"}};

/// (ux, uy, uz) of each cell, for readers that take a vector field (ParaView's glyphs and
/// stream lines); the components stay beside it for those that take scalars.
std::vector<double> velocity_vectors(const FieldSnapshot& f) {
  std::vector<double> v;
  v.reserve(3 * f.n.size());
  for (std::size_t c = 0; c < f.n.size(); ++c) v.insert(v.end(), {f.ux[c], f.uy[c], f.uz[c]});
  return v;
}

/// The XDMF 3 sidecar: a temporal collection of the snapshots, each an unstructured grid of the
/// shared hexahedra on its own corners, fields cell-centred; `file` is the HDF5 file's name.
std::string xdmf_text(const std::string& file, const Grid& g,
                      const std::vector<FieldSnapshot>& snapshots) {
  const std::size_t cells = g.interior_cells();
  const std::size_t points = static_cast<std::size_t>(g.nx + 1) * (g.ny + 1) * (g.nz + 1);
  std::string xdmf = "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n<Domain>\n"
                     "<Grid Name=\"fields\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (std::size_t s = 0; s < snapshots.size(); ++s) {
    const std::string group = fields_snapshot_group(s);
    // Time in shortest round-trip form, so that a reader gets the stored double.
    xdmf += fmt::format("<Grid Name=\"{}\" GridType=\"Uniform\">\n<Time Value=\"{}\"/>\n"
                        "<Topology TopologyType=\"Hexahedron\" NumberOfElements=\"{}\">\n",
                        group, snapshots[s].time, cells) +
            hdf_item(fmt::format("{} 8", cells), "Int", file, "hexahedra") +
            "</Topology>\n<Geometry GeometryType=\"XYZ\">\n" +
            hdf_item(fmt::format("{} 3", points), "Float", file, group + "/points") +
            "</Geometry>\n";
    for (const auto& column : field_columns)
      xdmf += fmt::format("<Attribute Name=\"{}\" AttributeType=\"Scalar\" Center=\"Cell\">\n",
                          column.name) +
              hdf_item(fmt::format("{} {} {}", g.nz, g.ny, g.nx), "Float", file,
                       group + "/" + column.name) +
              "</Attribute>\n";
    xdmf += "<Attribute Name=\"velocity\" AttributeType=\"Vector\" Center=\"Cell\">\n" +
            hdf_item(fmt::format("{} {} {} 3", g.nz, g.ny, g.nx), "Float", file, group + "/velocity") +
            "</Attribute>\n</Grid>\n";
  }
  return xdmf + "</Grid>\n</Domain>\n</Xdmf>\n";
}

}  // namespace

void write_fields(const std::filesystem::path& h5_path, const Grid& g,
                  const std::vector<FieldSnapshot>& snapshots, const RunRecord& run) {
  const std::size_t points = static_cast<std::size_t>(g.nx + 1) * (g.ny + 1) * (g.nz + 1);
  const std::vector<std::size_t> shape{static_cast<std::size_t>(g.nz),
                                       static_cast<std::size_t>(g.ny),
                                       static_cast<std::size_t>(g.nx)};
  write_hdf5_atomically(h5_path, [&](const hid_t root) {
    write_run_attributes(root, run);
    h5::write_attribute(root, file_kind_attribute, std::string(fields_file_kind));
    h5::write_attribute(root, "cell_size", g.h);
    h5::write_attribute(root, "nx", std::int64_t{g.nx});
    h5::write_attribute(root, "ny", std::int64_t{g.ny});
    h5::write_attribute(root, "nz", std::int64_t{g.nz});
    h5::write(root, "hexahedra", hexahedra(g), {g.interior_cells(), 8}, "1");
    for (std::size_t s = 0; s < snapshots.size(); ++s) {
      const FieldSnapshot& f = snapshots[s];
      h5::Handle group = h5::create_group(root, fields_snapshot_group(s));
      h5::write_attribute(group.id(), "time", f.time);
      h5::write_attribute(group.id(), "phase", f.phase);
      h5::write_attribute(group.id(), "plate_z", f.plate_z);
      h5::write_attribute(group.id(), "plate_v", f.plate_v);
      h5::write_attribute(group.id(), "cycle", f.cycle);
      h5::write(group.id(), "points", corners(g, f.plate_z), {points, 3}, "sigma");
      for (const auto& column : field_columns)
        h5::write(group.id(), column.name, f.*column.values, shape, column.units);
      h5::write(group.id(), "velocity", velocity_vectors(f), {shape[0], shape[1], shape[2], 3}, "sqrt(g sigma)");
    }
  });
  write_text_atomically(derived_name(h5_path, ".xdmf"), xdmf_text(h5_path.filename().string(), g, snapshots));
}

std::string fields_snapshot_group(std::size_t s) { return fmt::format("snapshot_{:03d}", s); }

}  // namespace shaker::continuum
