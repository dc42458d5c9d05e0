// The type tensors are stored in: float, or with FP16 (the fp16 shader variants) float16_t,
// which halves memory and memory traffic. Arithmetic stays fp32 where it accumulates (dot
// products, sums, softmax): values read are widened, results narrowed once when stored.
#ifdef FP16
#extension GL_EXT_shader_16bit_storage : require
#extension GL_EXT_shader_explicit_arithmetic_types_float16 : require
#define VALUE float16_t
#else
#define VALUE float
#endif
