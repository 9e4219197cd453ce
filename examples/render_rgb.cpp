// examples/render_rgb.cpp: the render loops of nsp_render for the rgb mode (render_job.hpp), in a
// translation unit of their own so that the three modes compile in parallel.
#include "render_job_impl.hpp"

namespace nsp_examples {
template RenderStats render_combination<nsp::Rgb>(std::size_t, const RenderRequest&, std::vector<float>&);
}  // namespace nsp_examples
