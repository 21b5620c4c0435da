#include "continuum/output.hpp"

#include <fmt/format.h>

#include <stdexcept>

#include "common/hdf5_file.hpp"

namespace shaker::continuum {

Profile horizontal_profile(const TimeIntegrator& solver, const ShakerKinematics& shaker) {
  const Grid& g = solver.op().grid();
  const State& s = solver.state();
  const double t = solver.time();
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

Diagnostics diagnostics(const TimeIntegrator& solver, const ShakerKinematics& shaker) {
  const Grid& g = solver.op().grid();
  const State& s = solver.state();
  const double t = solver.time();
  const double plate_z = shaker.position(t), plate_v = shaker.velocity(t);
  const double area_weight = g.dimension == 3 ? g.h * g.h * g.h / (g.nx * g.h * g.ny * g.h) : g.h;
  const double e = solver.op().settings().e;
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

FieldSnapshot snapshot(const TimeIntegrator& solver, const ShakerKinematics& shaker) {
  const Grid& g = solver.op().grid();
  FieldSnapshot f;
  f.time = solver.time();
  f.phase = shaker.phase(f.time);
  const double plate_v = shaker.velocity(f.time);
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const Primitive w = to_primitive(solver.state(), g.index(i, j, k));
        f.n.push_back(w.n);
        f.ux.push_back(w.ux);
        f.uy.push_back(w.uy);
        f.uz.push_back(w.uz + plate_v);
        f.T.push_back(w.T);
      }
  return f;
}

namespace {
void write_3d(hid_t group, const std::string& name, const std::vector<double>& data, const Grid& g) {
  const hsize_t dims[3] = {static_cast<hsize_t>(g.nz), static_cast<hsize_t>(g.ny),
                           static_cast<hsize_t>(g.nx)};
  h5::Handle space(H5Screate_simple(3, dims, nullptr));
  h5::Handle set(H5Dcreate2(group, name.c_str(), H5T_NATIVE_DOUBLE, space.id(), H5P_DEFAULT,
                            H5P_DEFAULT, H5P_DEFAULT));
  if (space.id() < 0 || set.id() < 0 ||
      H5Dwrite(set.id(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) < 0)
    throw std::runtime_error("HDF5: write dataset " + name + " failed");
}
}  // namespace

void write_fields(const std::filesystem::path& h5_path, const Grid& g,
                  const std::vector<FieldSnapshot>& snapshots) {
  std::string xdmf = "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n<Domain>\n"
                     "<Grid Name=\"fields\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  const std::string dims = fmt::format("{} {} {}", g.nz, g.ny, g.nx);
  const std::string node_dims = fmt::format("{} {} {}", g.nz + 1, g.ny + 1, g.nx + 1);
  write_hdf5_atomically(h5_path, [&](const hid_t file) {
    for (std::size_t s = 0; s < snapshots.size(); ++s) {
      const FieldSnapshot& f = snapshots[s];
      const std::string group_name = fmt::format("snapshot_{:03d}", s);
      h5::Handle group = h5::create_group(file, group_name);
      h5::write_attribute(group.id(), "time", f.time);
      h5::write_attribute(group.id(), "phase", f.phase);
      xdmf += fmt::format("<Grid Name=\"{}\" GridType=\"Uniform\">\n<Time Value=\"{}\"/>\n"
                          "<Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"{}\"/>\n"
                          "<Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n"
                          "<DataItem Dimensions=\"3\" Format=\"XML\">0 0 0</DataItem>\n"
                          "<DataItem Dimensions=\"3\" Format=\"XML\">{} {} {}</DataItem>\n"
                          "</Geometry>\n",
                          group_name, f.time, node_dims, g.h, g.h, g.h);
      const std::pair<const char*, const std::vector<double>*> fields[] = {
          {"n", &f.n}, {"ux", &f.ux}, {"uy", &f.uy}, {"uz", &f.uz}, {"T", &f.T}};
      for (const auto& [name, data] : fields) {
        write_3d(group.id(), name, *data, g);
        xdmf += fmt::format("<Attribute Name=\"{}\" AttributeType=\"Scalar\" Center=\"Cell\">\n"
                            "<DataItem Dimensions=\"{}\" NumberType=\"Float\" Precision=\"8\" "
                            "Format=\"HDF\">{}:/{}/{}</DataItem>\n</Attribute>\n",
                            name, dims, h5_path.filename().string(), group_name, name);
      }
      xdmf += "</Grid>\n";
    }
  });
  xdmf += "</Grid>\n</Domain>\n</Xdmf>\n";
  std::filesystem::path sidecar = h5_path;
  sidecar.replace_extension(".xdmf");
  write_text_atomically(sidecar, xdmf);
}

}  // namespace shaker::continuum
