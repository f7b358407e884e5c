#include "surfaces.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace hybrid_vo {
namespace render {
namespace {

// An albedo at least min_diff away from `other`, darker or lighter at random when both fit.
double contrasting(double other, double min_diff, Rng& rng) {
  const bool can_dark = other - min_diff >= 0.08, can_light = other + min_diff <= 0.95;
  const bool dark = can_dark && (!can_light || rng.chance(0.5));
  return dark ? rng.uniform(0.08, other - min_diff)
              : rng.uniform(std::min(other + min_diff, 0.95), 0.95);
}

// Ink for text or drawings on a background.
double ink_on(double background) { return background > 0.5 ? 0.1 : 0.92; }

bool overlaps(const std::vector<std::pair<double, double>>& intervals, double a, double b) {
  for (const auto& [lo, hi] : intervals)
    if (a < hi && b > lo) return true;
  return false;
}

// A wall canvas addressed by height above the floor instead of v.
struct WallCanvas {
  Canvas* c;
  double height;
  double paint;

  double v(double h) const { return height - h; }
  void rect(double u0, double h0, double u1, double h1, double albedo) const {
    c->rect(u0, v(h1), u1, v(h0), albedo);
  }
  void corner(double u, double h, std::vector<Eigen::Vector2d>* out) const {
    out->emplace_back(c->snap(u), c->snap(v(h)));
  }
};

void paint_text_block(Canvas* c, double u0, double v0, double u1, double v1, double cap,
                      double albedo, Rng& rng) {
  const double pitch = 2.1 * cap;
  for (double base = v0 + 1.2 * cap; base <= v1; base += pitch) {
    const double end = rng.chance(0.2) ? u1 - rng.uniform(0.0, 0.5 * (u1 - u0)) : u1;
    double u = u0;
    while (true) {
      const std::string word = random_word(rng, 1, 9, false);
      const double width = c->text_width(word, cap);
      if (u + width > end) break;
      c->text(word, u, base, cap, albedo);
      u += width + 0.9 * cap;
    }
  }
}

void paint_title(Canvas* c, double u0, double v0, double u1, double cap, double albedo, Rng& rng) {
  double u = u0;
  for (int i = 0; i < 3; ++i) {
    const std::string word = random_word(rng, 3, 7, true);
    const double width = c->text_width(word, cap, true);
    if (u + width > u1) break;
    c->text(word, u, v0 + cap, cap, albedo, true);
    u += width + 0.7 * cap;
  }
}

// A picture: shapes, a bar chart or a landscape.
void paint_picture(Canvas* c, double u0, double v0, double u1, double v1, Rng& rng) {
  const double bg = rng.uniform(0.15, 0.85);
  const double w = u1 - u0, h = v1 - v0;
  c->rect(u0, v0, u1, v1, bg);
  c->set_clip(u0, v0, u1, v1);
  const int kind = rng.uniform_int(0, 2);
  if (kind == 0) {
    const int n = rng.uniform_int(3, 8);
    for (int i = 0; i < n; ++i) {
      const double a = contrasting(bg, 0.2, rng);
      const double s = rng.uniform(0.12, 0.4) * std::min(w, h);
      const double cu = rng.uniform(u0 + s, u1 - s), cv = rng.uniform(v0 + s, v1 - s);
      const int shape = rng.uniform_int(0, 2);
      if (shape == 0) {
        c->circle(cu, cv, s, a);
      } else if (shape == 1) {
        c->rect(cu - s, cv - 0.7 * s, cu + s, cv + 0.7 * s, a);
      } else {
        c->polygon({{cu - s, cv + s}, {cu + s, cv + s}, {cu + rng.uniform(-s, s), cv - s}}, a);
      }
    }
  } else if (kind == 1) {
    const double ink = ink_on(bg);
    const int bars = rng.uniform_int(4, 9);
    const double bw = 0.8 * w / bars;
    for (int i = 0; i < bars; ++i) {
      const double top = v1 - 0.1 * h - rng.uniform(0.15, 0.8) * h;
      c->rect(u0 + 0.12 * w + i * bw, top, u0 + 0.12 * w + (i + 0.7) * bw, v1 - 0.1 * h,
              contrasting(bg, 0.25, rng));
    }
    c->rect(u0 + 0.1 * w, v1 - 0.1 * h, u1 - 0.05 * w, v1 - 0.1 * h + 0.006, ink);
    c->rect(u0 + 0.1 * w, v0 + 0.05 * h, u0 + 0.1 * w + 0.006, v1 - 0.1 * h, ink);
  } else {
    const double horizon = v0 + rng.uniform(0.45, 0.7) * h;
    for (int i = 0; i < 3; ++i) {
      const double peak_u = rng.uniform(u0, u1), peak_v = rng.uniform(v0 + 0.15 * h, horizon);
      const double half = rng.uniform(0.2, 0.5) * w;
      c->polygon({{peak_u - half, horizon}, {peak_u, peak_v}, {peak_u + half, horizon}},
                 contrasting(bg, 0.15, rng));
    }
    c->rect(u0, horizon, u1, v1, contrasting(bg, 0.2, rng));
    c->circle(rng.uniform(u0 + 0.2 * w, u1 - 0.2 * w), v0 + 0.15 * h, 0.07 * h,
              std::min(0.95, bg + 0.3));
  }
  c->clear_clip();
  c->grain(u0, v0, u1, v1, 0.01, rng.next());
}

void paint_poster(const WallCanvas& w, double u0, double h0, double width, double height, Rng& rng,
                  std::vector<Eigen::Vector2d>* corners) {
  Canvas* c = w.c;
  const double u1 = u0 + width, h1 = h0 + height;
  double bg = 0.0, inset = 0.0;
  if (rng.chance(0.5)) {  // framed print on a white mount
    const double frame = rng.uniform(0.015, 0.03);
    w.rect(u0, h0, u1, h1, rng.uniform(0.06, std::min(0.25, w.paint - 0.25)));
    bg = rng.uniform(0.86, 0.93);
    w.rect(u0 + frame, h0 + frame, u1 - frame, h1 - frame, bg);
    inset = frame + 0.035;
  } else {
    bg = w.paint < 0.64 ? rng.uniform(0.86, 0.95) : rng.uniform(0.12, 0.35);
    w.rect(u0, h0, u1, h1, bg);
    inset = 0.03;
  }
  const double cu0 = u0 + inset, cu1 = u1 - inset;
  double v = w.v(h1) + inset;
  const double v_end = w.v(h0) - inset;
  const double ink = ink_on(bg);
  const double title = std::min(0.06, 0.1 * (cu1 - cu0));
  paint_title(c, cu0, v, cu1, title, ink, rng);
  v += 1.8 * title;
  const double picture_h = rng.uniform(0.35, 0.55) * (v_end - v);
  if (rng.chance(0.6)) {
    paint_picture(c, cu0, v, cu1, v + picture_h, rng);
    paint_text_block(c, cu0, v + picture_h + 0.02, cu1, v_end, rng.uniform(0.012, 0.018), ink, rng);
  } else {
    paint_text_block(c, cu0, v, cu1, v_end - picture_h - 0.02, rng.uniform(0.012, 0.018), ink, rng);
    paint_picture(c, cu0, v_end - picture_h, cu1, v_end, rng);
  }
  for (double hh : {h0, h1})
    for (double uu : {u0, u1}) w.corner(uu, hh, corners);
}

void paint_door(const WallCanvas& w, double u0, double width, Rng& rng,
                std::vector<Eigen::Vector2d>* corners) {
  Canvas* c = w.c;
  const double u1 = u0 + width;
  const double top = std::min(2.1, w.height - 0.3), arch = 0.07;
  const double frame = contrasting(w.paint, 0.2, rng);
  w.rect(u0 - arch, 0.0, u1 + arch, top + arch, frame);
  const bool wood = rng.chance(0.5);
  double leaf = wood ? rng.uniform(0.28, 0.5) : rng.uniform(0.6, 0.85);
  if (std::abs(leaf - frame) < 0.12) leaf = frame > 0.5 ? frame - 0.25 : frame + 0.25;
  w.rect(u0, 0.0, u1, top, leaf);
  if (wood) c->mottle(u0, w.v(top), u1, w.v(0.0), 0.08, 0.03, rng.next(), 1.0, 12.0);
  c->grain(u0, w.v(top), u1, w.v(0.0), 0.008, rng.next());
  // Raised panels: light top-left edges and dark bottom-right ones.
  const double m = 0.12, bevel = 0.012;
  const double split = 0.5 * top;
  const bool glass = rng.chance(0.3);
  for (int panel = 0; panel < 2; ++panel) {
    const double p0 = panel == 0 ? 0.2 : split + 0.08, p1 = panel == 0 ? split - 0.08 : top - m;
    if (panel == 1 && glass) {
      w.rect(u0 + m, p0, u1 - m, p1, rng.uniform(0.12, 0.25));
      const double span = p1 - p0;
      c->polygon({{u0 + m, w.v(p0 + 0.3 * span)},
                  {u0 + m, w.v(p0 + 0.5 * span)},
                  {u1 - m, w.v(p0 + 0.9 * span)},
                  {u1 - m, w.v(p0 + 0.7 * span)}},
                 0.4);
      c->frame(u0 + m, w.v(p1), u1 - m, w.v(p0), 0.015, std::min(0.95, leaf + 0.1));
      continue;
    }
    w.rect(u0 + m, p1 - bevel, u1 - m, p1, std::min(0.95, leaf * 1.3));
    w.rect(u0 + m, p0, u0 + m + bevel, p1, std::min(0.95, leaf * 1.3));
    w.rect(u0 + m, p0, u1 - m, p0 + bevel, leaf * 0.6);
    w.rect(u1 - m - bevel, p0, u1 - m, p1, leaf * 0.6);
  }
  // Gap around the leaf, kick plate, handle.
  c->frame(u0, w.v(top), u1, w.v(0.0), 1.0 / c->tpm(), 0.08);
  w.rect(u0 + 0.02, 0.0, u1 - 0.02, 0.2, 0.72);
  const bool left = rng.chance(0.5);
  const double hu = left ? u0 + 0.06 : u1 - 0.1;
  const double metal = leaf > 0.5 ? 0.15 : 0.85;
  w.rect(hu, 0.9, hu + 0.04, 1.12, metal);
  w.rect(left ? hu : hu - 0.1, 1.02, left ? hu + 0.14 : hu + 0.04, 1.045, metal);
  // Room sign beside the door, light switch on the other side.
  const double sign_u = left ? u1 + arch + 0.08 : u0 - arch - 0.23;
  w.rect(sign_u, 1.45, sign_u + 0.15, 1.55, 0.15);
  c->text(std::to_string(rng.uniform_int(1, 3)) + "." + std::to_string(rng.uniform_int(10, 49)),
          sign_u + 0.02, w.v(1.48), 0.035, 0.9);
  const double sw_u = left ? u0 - arch - 0.14 : u1 + arch + 0.06;
  w.rect(sw_u, 1.0, sw_u + 0.08, 1.08, 0.9);
  c->frame(sw_u, w.v(1.08), sw_u + 0.08, w.v(1.0), 1.0 / c->tpm(), 0.55);
  w.rect(sw_u + 0.025, 1.015, sw_u + 0.055, 1.065, 0.8);
  w.corner(u0 - arch, top + arch, corners);
  w.corner(u1 + arch, top + arch, corners);
}

// A window with a view of a street: sky, buildings with their own windows.
void paint_window(const WallCanvas& w, double u0, double width, double sill, double head, Rng& rng,
                  std::vector<Eigen::Vector2d>* corners) {
  Canvas* c = w.c;
  const double u1 = u0 + width, fw = 0.06;
  const double frame = w.paint > 0.62 ? rng.uniform(0.2, 0.35) : rng.uniform(0.88, 0.95);
  w.rect(u0, sill, u1, head, frame);
  const double g0 = u0 + fw, g1 = u1 - fw, gb = sill + fw, gt = head - fw;
  // Sky: brighter towards the top.
  const double step = 1.0 / c->tpm();
  for (double h = gb; h < gt; h += step)
    w.rect(g0, h, g1, h + step, 0.78 + 0.17 * (h - gb) / (gt - gb));
  for (double u = g0 - rng.uniform(0.0, 0.3); u < g1;) {
    const double bw = rng.uniform(0.15, 0.45);
    const double bh = rng.uniform(0.2, 0.85) * (gt - gb);
    const double a = rng.uniform(0.25, 0.6);
    const double bu0 = std::max(u, g0), bu1 = std::min(u + bw, g1);
    if (bu1 - bu0 > 0.02) {
      w.rect(bu0, gb, bu1, gb + bh, a);
      const double wa = a > 0.45 ? a - 0.2 : a + 0.25;
      for (double wh = gb + 0.04; wh + 0.05 < gb + bh - 0.03; wh += 0.08)
        for (double wu = u + 0.03; wu + 0.03 < u + bw - 0.02; wu += 0.06)
          if (wu > g0 && wu + 0.03 < g1) w.rect(wu, wh, wu + 0.03, wh + 0.045, wa);
    }
    u += bw + rng.uniform(0.0, 0.1);
  }
  c->grain(g0, w.v(gt), g1, w.v(gb), 0.01, rng.next());
  // Mullion and transom.
  if (width > 1.2) w.rect(0.5 * (u0 + u1) - 0.025, gb, 0.5 * (u0 + u1) + 0.025, gt, frame);
  const double transom = gb + 0.68 * (gt - gb);
  w.rect(g0, transom - 0.025, g1, transom + 0.025, frame);
  // Sill ledge.
  w.rect(u0 - 0.05, sill - 0.04, u1 + 0.05, sill, std::min(0.95, frame + 0.05));
  w.corner(u0, head, corners);
  w.corner(u1, head, corners);
}

// A cork board with pinned sheets, a few of them askew.
void paint_board(const WallCanvas& w, double u0, double h0, double width, double height, Rng& rng,
                 std::vector<Eigen::Vector2d>* corners) {
  Canvas* c = w.c;
  const double u1 = u0 + width, h1 = h0 + height, fw = 0.03;
  const double frame = w.paint > 0.6 ? rng.uniform(0.2, 0.32) : rng.uniform(0.85, 0.93);
  w.rect(u0, h0, u1, h1, frame);
  const double cork = frame > 0.5 ? rng.uniform(0.35, 0.45) : rng.uniform(0.5, 0.58);
  w.rect(u0 + fw, h0 + fw, u1 - fw, h1 - fw, cork);
  c->grain(u0 + fw, w.v(h1 - fw), u1 - fw, w.v(h0 + fw), 0.05, rng.next());
  const int sheets = rng.uniform_int(4, 8);
  for (int i = 0; i < sheets; ++i) {
    const bool portrait = rng.chance(0.6);
    const double sw = portrait ? 0.21 : 0.297, sh = portrait ? 0.297 : 0.21;
    if (sw > width - 2 * fw - 0.04 || sh > height - 2 * fw - 0.04) continue;
    const double su = rng.uniform(u0 + fw + 0.02, u1 - fw - 0.02 - sw);
    const double sv = rng.uniform(w.v(h1) + fw + 0.02, w.v(h0) - fw - 0.02 - sh);
    const double paper = rng.uniform(0.82, 0.95);
    if (rng.chance(0.25)) {
      const double a = rng.uniform(0.05, 0.14) * (rng.chance(0.5) ? 1 : -1);
      const double cu = su + 0.5 * sw, cv = sv + 0.5 * sh, ca = std::cos(a), sa = std::sin(a);
      std::vector<Eigen::Vector2d> pts;
      for (const auto& [du, dv] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
        const double x = 0.5 * sw * du, y = 0.5 * sh * dv;
        pts.emplace_back(cu + ca * x - sa * y, cv + sa * x + ca * y);
      }
      c->polygon(pts, paper);
    } else {
      c->rect(su, sv, su + sw, sv + sh, paper);
      paint_title(c, su + 0.02, sv + 0.02, su + sw - 0.02, 0.02, 0.12, rng);
      paint_text_block(c, su + 0.02, sv + 0.06, su + sw - 0.02, sv + sh - 0.03, 0.008, 0.2, rng);
    }
    c->circle(su + 0.5 * sw, sv + 0.012, 0.006, rng.chance(0.5) ? 0.1 : 0.8);
  }
  for (double hh : {h0, h1})
    for (double uu : {u0, u1}) w.corner(uu, hh, corners);
}

void paint_radiator(const WallCanvas& w, double u0, double width, Rng& rng) {
  const double u1 = u0 + width, h0 = 0.15, h1 = rng.uniform(0.55, 0.7);
  const double panel = rng.uniform(0.8, 0.9);
  w.rect(u0, h0, u1, h1, panel);
  for (double u = u0 + 0.03; u + 0.012 < u1 - 0.02; u += 0.05)
    w.rect(u, h0 + 0.03, u + 0.012, h1 - 0.04, panel - 0.25);
  w.rect(u0, h1 - 0.04, u1, h1 - 0.03, panel - 0.15);
  for (double pu : {u0 + 0.02, u1 - 0.045}) w.rect(pu, 0.0, pu + 0.025, h0, panel - 0.1);
  w.c->circle(u1 - 0.032, w.v(h0 - 0.05), 0.02, 0.3);
}

void paint_socket(const WallCanvas& w, double u0) {
  w.rect(u0, 0.25, u0 + 0.08, 0.33, 0.9);
  w.c->frame(u0, w.v(0.33), u0 + 0.08, w.v(0.25), 1.0 / w.c->tpm(), 0.55);
  w.c->circle(u0 + 0.028, w.v(0.29), 0.005, 0.15);
  w.c->circle(u0 + 0.052, w.v(0.29), 0.005, 0.15);
}

}  // namespace

void paint_wall(Canvas* canvas, const WallLayout& layout, Rng& rng,
                std::vector<Eigen::Vector2d>* corners) {
  const double L = layout.length, H = layout.height;
  const WallCanvas w{canvas, H, rng.uniform(0.52, 0.74)};
  canvas->rect(0.0, 0.0, L, H, w.paint);
  canvas->mottle(0.0, 0.0, L, H, 0.035, 0.7, rng.next());
  canvas->grain(0.0, 0.0, L, H, 0.006, rng.next());

  // A dado: painted in a second colour with a rail, or tiled.
  const int dado = rng.uniform_int(0, 2);
  double dado_top = 0.0;
  if (dado == 1) {
    const double top = rng.uniform(0.9, 1.15);
    dado_top = top + 0.03;
    const double a = contrasting(w.paint, 0.15, rng);
    w.rect(0.0, 0.0, L, top, a);
    canvas->mottle(0.0, w.v(top), L, H, 0.03, 0.5, rng.next());
    w.rect(0.0, top - 0.02, L, top + 0.03, a > 0.5 ? a - 0.3 : a + 0.3);
  } else if (dado == 2) {
    const double tile = rng.chance(0.5) ? 0.15 : 0.2;
    const double top = tile * std::round(1.2 / tile);
    dado_top = top + 0.025;
    const double base = rng.uniform(0.72, 0.88);
    const double grout = std::max(0.004, 1.0 / canvas->tpm());
    for (int i = 0; i * tile < L; ++i)
      for (int j = 0; (j + 1) * tile <= top + 1e-9; ++j)
        w.rect(i * tile, j * tile, (i + 1) * tile, (j + 1) * tile, base + rng.uniform(-0.04, 0.04));
    for (int i = 1; i * tile < L; ++i)
      w.rect(i * tile - 0.5 * grout, 0.0, i * tile + 0.5 * grout, top, 0.45);
    for (int j = 1; j * tile < top - 1e-9; ++j)
      w.rect(0.0, j * tile - 0.5 * grout, L, j * tile + 0.5 * grout, 0.45);
    w.rect(0.0, top, L, top + 0.025, rng.uniform(0.3, 0.45));
  }
  // Skirting board with a lit top lip.
  const double skirt_h = rng.uniform(0.07, 0.12);
  const double skirt = rng.chance(0.7) ? rng.uniform(0.12, 0.28) : rng.uniform(0.86, 0.93);
  w.rect(0.0, 0.0, L, skirt_h, skirt);
  w.rect(0.0, skirt_h - 0.008, L, skirt_h, std::min(0.95, skirt + 0.15));

  // Doors, windows, posters, boards and radiators along the wall.
  std::vector<std::pair<double, double>> used;
  // Posters and boards clear the furniture and the dado, so their lower corners stay sharp.
  const double poster_floor = std::max({1.05, layout.blocked_height + 0.12, dado_top + 0.1});
  for (double u = rng.uniform(0.3, 1.2);;) {
    const double pick = rng.uniform();
    int type = pick < 0.3 ? 0 : pick < 0.6 ? 1 : pick < 0.78 ? 2 : pick < 0.9 ? 3 : 4;
    if (type == 2 && !layout.exterior) type = 1;
    double width = 0.0;
    switch (type) {
      case 0:
        width = rng.uniform(0.8, 1.0) + 0.14;
        break;  // door with its architrave
      case 1:
        width = rng.uniform(0.45, 0.85);
        break;
      case 2:
        width = rng.uniform(1.0, 1.8);
        break;
      case 3:
        width = rng.uniform(0.9, 1.5);
        break;
      default:
        width = rng.uniform(0.8, 1.5);
        break;
    }
    if (u + width > L - 0.3) break;
    const bool blocked = overlaps(layout.blocked, u - 0.1, u + width + 0.1);
    if (blocked && (type == 0 || type == 2 || type == 4)) {
      type = 1;
      width = std::min(width, 0.8);
    }
    switch (type) {
      case 0:
        paint_door(w, u + 0.07, width - 0.14, rng, corners);
        break;
      case 1: {
        const double h = std::min(rng.uniform(0.6, 1.0), H - 0.35 - poster_floor);
        if (h < 0.3) break;
        const double h0 = std::max(poster_floor, rng.uniform(1.5, 1.6) - 0.5 * h);
        paint_poster(w, u, std::min(h0, H - 0.3 - h), width, h, rng, corners);
        break;
      }
      case 2: {
        const double head = std::min(2.2, H - 0.25);
        paint_radiator(w, u + 0.1, width - 0.2, rng);
        paint_window(w, u, width, 0.9, head, rng, corners);
        break;
      }
      case 3: {
        const double h = std::min(rng.uniform(0.6, 1.0), H - 0.35 - poster_floor);
        if (h < 0.35) break;
        const double h0 = std::max(poster_floor, 1.5 - 0.5 * h);
        paint_board(w, u, std::min(h0, H - 0.3 - h), width, h, rng, corners);
        break;
      }
      default:
        paint_radiator(w, u, width, rng);
        break;
    }
    used.emplace_back(u - 0.25, u + width + 0.25);
    u += width + rng.uniform(0.5, 1.6);
  }
  for (double u = rng.uniform(0.5, 2.0); u < L - 0.4; u += rng.uniform(2.0, 4.0))
    if (!overlaps(used, u, u + 0.08) && !overlaps(layout.blocked, u, u + 0.08)) paint_socket(w, u);
}

void paint_floor(Canvas* c, const Quad& quad, const FloorStyle& style) {
  const double x0 = quad.origin.x(), x1 = x0 + quad.size_u;
  const double y1 = quad.origin.y(), y0 = y1 - quad.size_v;
  // World x, y to canvas u, v (u = x - x0, v = y1 - y); rect() orders its corners itself.
  auto rect = [&](double xa, double ya, double xb, double yb, double albedo) {
    c->rect(xa - x0, y1 - ya, xb - x0, y1 - yb, albedo);
  };
  const double gap = std::max(0.004, 1.0 / c->tpm());
  if (!style.planks) {
    const double T = style.tile;
    const int i0 = static_cast<int>(std::floor(x0 / T)), i1 = static_cast<int>(std::ceil(x1 / T));
    const int j0 = static_cast<int>(std::floor(y0 / T)), j1 = static_cast<int>(std::ceil(y1 / T));
    for (int i = i0; i < i1; ++i) {
      for (int j = j0; j < j1; ++j) {
        Rng tile(hash_mix(style.seed, hash_mix(static_cast<uint64_t>(i + 100000),
                                               static_cast<uint64_t>(j + 100000))));
        const double checker = style.checker && ((i + j) & 1) ? -0.22 : 0.0;
        const double a = style.base + checker + tile.uniform(-0.04, 0.04);
        rect(i * T, j * T, (i + 1) * T, (j + 1) * T, a);
        // Terrazzo chips.
        for (int k = 0; k < 22; ++k) {
          const double x = (i + tile.uniform(0.02, 0.98)) * T;
          const double y = (j + tile.uniform(0.02, 0.98)) * T;
          c->circle(x - x0, y1 - y, tile.uniform(0.003, 0.009), a + tile.uniform(-0.2, 0.2));
        }
      }
    }
    c->grain(0.0, 0.0, quad.size_u, quad.size_v, 0.01, hash_mix(style.seed, 7));
    for (int i = i0; i <= i1; ++i) rect(i * T - 0.5 * gap, y0, i * T + 0.5 * gap, y1, 0.2);
    for (int j = j0; j <= j1; ++j) rect(x0, j * T - 0.5 * gap, x1, j * T + 0.5 * gap, 0.2);
  } else {
    const double P = style.tile;
    const int j0 = static_cast<int>(std::floor(y0 / P)), j1 = static_cast<int>(std::ceil(y1 / P));
    for (int j = j0; j < j1; ++j) {
      Rng row(hash_mix(style.seed, static_cast<uint64_t>(j + 100000)));
      for (double x = -row.uniform(0.0, 2.0); x < x1;) {
        const double len = row.uniform(0.9, 2.0);
        const double a = style.base + row.uniform(-0.08, 0.08);
        const uint64_t grain_seed = row.next();
        if (x + len > x0) {
          rect(x, j * P, x + len, (j + 1) * P, a);
          c->mottle(std::max(x, x0) - x0, y1 - (j + 1) * P, std::min(x + len, x1) - x0, y1 - j * P,
                    0.12, 0.02, grain_seed, 15.0, 1.0);
          rect(x + len - 0.5 * gap, j * P, x + len + 0.5 * gap, (j + 1) * P, 0.12);
        }
        x += len;
      }
      rect(x0, j * P - 0.5 * gap, x1, j * P + 0.5 * gap, 0.12);
    }
  }
  if (style.rug) {
    const Eigen::Vector2d a = style.rug_min, b = style.rug_max;
    rect(a.x(), a.y(), b.x(), b.y(), 0.2);
    rect(a.x() + 0.08, a.y() + 0.08, b.x() - 0.08, b.y() - 0.08, 0.72);
    rect(a.x() + 0.13, a.y() + 0.13, b.x() - 0.13, b.y() - 0.13, 0.42);
    for (double x = a.x() + 0.3; x + 0.08 < b.x() - 0.2; x += 0.25)
      for (double y = a.y() + 0.3; y + 0.08 < b.y() - 0.2; y += 0.25)
        rect(x, y, x + 0.08, y + 0.08, 0.25);
    c->grain(a.x() - x0, y1 - b.y(), b.x() - x0, y1 - a.y(), 0.03, hash_mix(style.seed, 11));
  }
  c->mottle(0.0, 0.0, quad.size_u, quad.size_v, 0.05, 1.2, hash_mix(style.seed, 13));
}

void paint_ceiling(Canvas* c, const Quad& quad, const std::vector<Light>& lights, uint64_t seed) {
  const double x0 = quad.origin.x(), y0 = quad.origin.y();
  const double x1 = x0 + quad.size_u, y1 = y0 + quad.size_v;
  auto rect = [&](double xa, double ya, double xb, double yb, double albedo) {
    c->rect(xa - x0, ya - y0, xb - x0, yb - y0, albedo);
  };
  Rng rng(seed);
  const double panel = 0.74;
  c->rect(0.0, 0.0, quad.size_u, quad.size_v, panel);
  // Fissured acoustic panels.
  const int dots = static_cast<int>(120 * quad.size_u * quad.size_v);
  for (int k = 0; k < dots; ++k)
    c->circle(rng.uniform(0.0, quad.size_u), rng.uniform(0.0, quad.size_v),
              rng.uniform(0.002, 0.005), panel - rng.uniform(0.1, 0.25));
  c->grain(0.0, 0.0, quad.size_u, quad.size_v, 0.01, rng.next());
  // The T-bar grid, world-anchored, with a shadow line on one side.
  const double G = 0.6, bar = 0.024, shadow = std::max(0.004, 1.0 / c->tpm());
  for (int i = static_cast<int>(std::floor(x0 / G)); i * G <= x1; ++i) {
    rect(i * G - 0.5 * bar, y0, i * G + 0.5 * bar, y1, 0.9);
    rect(i * G + 0.5 * bar, y0, i * G + 0.5 * bar + shadow, y1, 0.5);
  }
  for (int j = static_cast<int>(std::floor(y0 / G)); j * G <= y1; ++j) {
    rect(x0, j * G - 0.5 * bar, x1, j * G + 0.5 * bar, 0.9);
    rect(x0, j * G + 0.5 * bar, x1, j * G + 0.5 * bar + shadow, 0.5);
  }
  // Sprinklers and smoke detectors at some panel centres.
  for (int i = static_cast<int>(std::floor(x0 / G)); i * G < x1; ++i)
    for (int j = static_cast<int>(std::floor(y0 / G)); j * G < y1; ++j) {
      Rng cell(hash_mix(seed, hash_mix(static_cast<uint64_t>(i + 1000), j + 1000)));
      if (!cell.chance(0.08)) continue;
      const double cx = (i + 0.5) * G - x0, cy = (j + 0.5) * G - y0;
      c->circle(cx, cy, 0.05, 0.92);
      c->circle(cx, cy, 0.03, 0.45);
      c->circle(cx, cy, 0.012, 0.9);
    }
  // Louvred light fixtures.
  for (const Light& light : lights) {
    const Eigen::Vector2d lo = light.position.head<2>() - light.half_extent;
    const Eigen::Vector2d hi = light.position.head<2>() + light.half_extent;
    if (hi.x() < x0 || lo.x() > x1 || hi.y() < y0 || lo.y() > y1) continue;
    rect(lo.x(), lo.y(), hi.x(), hi.y(), 0.6);
    rect(lo.x() + 0.025, lo.y() + 0.025, hi.x() - 0.025, hi.y() - 0.025, 1.0);
    const bool along_x = light.half_extent.x() > light.half_extent.y();
    if (along_x) {
      for (double x = lo.x() + 0.08; x < hi.x() - 0.05; x += 0.08)
        rect(x, lo.y() + 0.025, x + 0.01, hi.y() - 0.025, 0.82);
    } else {
      for (double y = lo.y() + 0.08; y < hi.y() - 0.05; y += 0.08)
        rect(lo.x() + 0.025, y, hi.x() - 0.025, y + 0.01, 0.82);
    }
  }
}

void paint_cabinet_face(Canvas* c, double albedo, bool front, bool top, Rng& rng) {
  const double U = c->size_u(), V = c->size_v();
  c->rect(0.0, 0.0, U, V, albedo);
  c->mottle(0.0, 0.0, U, V, 0.03, 0.3, rng.next());
  c->grain(0.0, 0.0, U, V, 0.008, rng.next());
  const double edge = albedo * 0.7, dark = albedo * 0.35;
  const double handle = albedo > 0.5 ? 0.15 : 0.85;
  if (top) {
    c->frame(0.0, 0.0, U, V, 0.015, edge);
    if (U > 0.4 && V > 0.35) {
      const double pu = rng.uniform(0.05, U - 0.26), pv = rng.uniform(0.03, V - 0.33);
      c->rect(pu, pv, pu + 0.21, pv + 0.297, 0.92);
      paint_text_block(c, pu + 0.02, pv + 0.03, pu + 0.19, pv + 0.27, 0.008, 0.2, rng);
    }
    return;
  }
  if (front) {
    const double plinth = 0.06;
    if (rng.chance(0.5)) {
      const int n = std::max(2, static_cast<int>(std::round((V - plinth) / 0.28)));
      const double step = (V - plinth) / n;
      for (int i = 0; i < n; ++i) {
        const double v = i * step;
        if (i > 0) c->rect(0.02, v - 0.003, U - 0.02, v + 0.003, dark);
        c->rect(0.5 * U - 0.07, v + 0.05, 0.5 * U + 0.07, v + 0.07, handle);
      }
    } else {
      const int doors = U > 0.7 ? 2 : 1;
      for (int d = 1; d < doors; ++d)
        c->rect(d * U / doors - 0.003, 0.02, d * U / doors + 0.003, V - plinth, dark);
      for (int d = 0; d < doors; ++d) {
        const double hu = doors == 1 ? U - 0.08 : (d == 0 ? 0.5 * U - 0.06 : 0.5 * U + 0.04);
        c->rect(hu, 0.12, hu + 0.02, 0.28, handle);
      }
    }
    c->rect(0.0, V - plinth, U, V, 0.12);
  } else {
    c->rect(0.0, V - 0.06, U, V, 0.12);
  }
  c->frame(0.0, 0.0, U, V, 0.02, edge);
}

void paint_pillar_face(Canvas* c, Rng& rng, std::vector<Eigen::Vector2d>* corners) {
  const double U = c->size_u(), H = c->size_v();
  const WallCanvas w{c, H, rng.uniform(0.62, 0.74)};
  c->rect(0.0, 0.0, U, H, w.paint);
  c->mottle(0.0, 0.0, U, H, 0.03, 0.5, rng.next());
  c->grain(0.0, 0.0, U, H, 0.006, rng.next());
  w.rect(0.0, 0.0, 0.03, 1.4, 0.4);  // corner guards
  w.rect(U - 0.03, 0.0, U, 1.4, 0.4);
  w.rect(0.0, 0.0, U, 0.1, 0.18);
  if (U >= 0.4) paint_poster(w, 0.07, 1.2, U - 0.14, std::min(0.7, H - 1.5), rng, corners);
}

}  // namespace render
}  // namespace hybrid_vo
