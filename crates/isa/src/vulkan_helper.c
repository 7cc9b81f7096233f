/* specula-isa's Vulkan helper: one compute pipeline from a SPIR-V file, on whichever driver
 * the loader was pointed at (the Rust side sets VK_ICD_FILENAMES).
 *
 *   vulkan_helper device               the driver's device, one line
 *   vulkan_helper isa ENTRY FILE.spv...
 *                                      each file's pipeline's executables as the driver
 *                                      reports them (VK_KHR_pipeline_executable_properties):
 *                                      statistics and internal representations (RADV: NIR,
 *                                      ACO IR, the assembly), on stdout, one device for all
 *   vulkan_helper run FILE.spv ENTRY INPUTS_PER_THREAD
 *                                      the kernel run over the f32s on stdin (binding 0, read)
 *                                      into as many threads' f32s on stdout (binding 1)
 *
 * Output of `isa`, line-oriented for the Rust side to read:
 *   device NAME
 *   kernel FILE.spv                    before each file's
 *   stat NAME<TAB>VALUE
 *   ir NAME<TAB>BYTES, then exactly BYTES bytes of text and a newline
 * Errors go to stderr, one line, and exit 1. */
#include <vulkan/vulkan.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define WORKGROUP 64

static int fail(const char *what, VkResult result) {
    fprintf(stderr, "%s failed (VkResult %d)\n", what, (int)result);
    return 1;
}
#define CHECK(call) do { VkResult r_ = (call); if (r_ != VK_SUCCESS) return fail(#call, r_); } while (0)

static void *read_all(FILE *file, size_t *size) {
    size_t capacity = 1 << 16, length = 0;
    char *data = malloc(capacity);
    size_t got;
    while (data && (got = fread(data + length, 1, capacity - length, file)) > 0) {
        length += got;
        if (length == capacity) {
            capacity *= 2;
            data = realloc(data, capacity);
        }
    }
    *size = length;
    return data;
}

static uint32_t memory_type(VkPhysicalDevice physical, uint32_t allowed, VkMemoryPropertyFlags wanted) {
    VkPhysicalDeviceMemoryProperties properties;
    vkGetPhysicalDeviceMemoryProperties(physical, &properties);
    for (uint32_t i = 0; i < properties.memoryTypeCount; i++)
        if ((allowed & (1u << i)) && (properties.memoryTypes[i].propertyFlags & wanted) == wanted)
            return i;
    return UINT32_MAX;
}

int main(int argc, char **argv) {
    int device_only = argc == 2 && !strcmp(argv[1], "device");
    if (!device_only && (argc < 4 || (strcmp(argv[1], "isa") && strcmp(argv[1], "run")) || (!strcmp(argv[1], "run") && argc < 5))) {
        fprintf(stderr, "usage: vulkan_helper device | isa ENTRY FILE.spv... | run FILE.spv ENTRY INPUTS_PER_THREAD\n");
        return 2;
    }
    int isa = !strcmp(argv[1], "isa");

    VkApplicationInfo app = {VK_STRUCTURE_TYPE_APPLICATION_INFO, NULL, "specula", 1, "specula", 1, VK_API_VERSION_1_1};
    VkInstanceCreateInfo instance_info = {VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO, NULL, 0, &app, 0, NULL, 0, NULL};
    VkInstance instance;
    CHECK(vkCreateInstance(&instance_info, NULL, &instance));
    uint32_t count = 1;
    VkPhysicalDevice physical;
    VkResult listed = vkEnumeratePhysicalDevices(instance, &count, &physical);
    if ((listed != VK_SUCCESS && listed != VK_INCOMPLETE) || count == 0) {
        fprintf(stderr, "the Vulkan driver offers no device\n");
        return 1;
    }
    VkPhysicalDeviceProperties properties;
    vkGetPhysicalDeviceProperties(physical, &properties);
    if (isa || device_only)
        printf("device %s (Mesa driver %u.%u.%u)\n", properties.deviceName, VK_API_VERSION_MAJOR(properties.driverVersion),
               VK_API_VERSION_MINOR(properties.driverVersion), VK_API_VERSION_PATCH(properties.driverVersion));
    if (device_only)
        return 0;

    float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info = {VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO, NULL, 0, 0, 1, &priority};
    VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR executables = {
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR, NULL, VK_TRUE};
    const char *extension = "VK_KHR_pipeline_executable_properties";
    VkDeviceCreateInfo device_info = {VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, isa ? &executables : NULL, 0, 1,
                                      &queue_info, 0, NULL, isa ? 1 : 0, isa ? &extension : NULL, NULL};
    VkDevice device;
    CHECK(vkCreateDevice(physical, &device_info, NULL, &device));

    VkDescriptorSetLayoutBinding bindings[2] = {
        {0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, NULL},
        {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, NULL}};
    VkDescriptorSetLayoutCreateInfo set_layout_info = {VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO, NULL, 0, 2, bindings};
    VkDescriptorSetLayout set_layout;
    CHECK(vkCreateDescriptorSetLayout(device, &set_layout_info, NULL, &set_layout));
    VkPipelineLayoutCreateInfo layout_info = {VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO, NULL, 0, 1, &set_layout, 0, NULL};
    VkPipelineLayout layout;
    CHECK(vkCreatePipelineLayout(device, &layout_info, NULL, &layout));
    int first = isa ? 3 : 2, last = isa ? argc : 3;
    const char *entry = isa ? argv[2] : argv[3];
    for (int f = first; f < last; f++) {
        FILE *file = fopen(argv[f], "rb");
        if (!file) {
            fprintf(stderr, "cannot open %s\n", argv[f]);
            return 1;
        }
        size_t code_size;
        uint32_t *code = read_all(file, &code_size);
        fclose(file);
        VkShaderModuleCreateInfo module_info = {VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO, NULL, 0, code_size, code};
        VkShaderModule module;
        CHECK(vkCreateShaderModule(device, &module_info, NULL, &module));
        VkComputePipelineCreateInfo pipeline_info = {
            VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO, NULL,
            isa ? VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR | VK_PIPELINE_CREATE_CAPTURE_INTERNAL_REPRESENTATIONS_BIT_KHR : 0,
            {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, NULL, 0, VK_SHADER_STAGE_COMPUTE_BIT, module, entry, NULL},
            layout, VK_NULL_HANDLE, -1};
        VkPipeline pipeline;
        CHECK(vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &pipeline_info, NULL, &pipeline));

        if (isa) {
            PFN_vkGetPipelineExecutablePropertiesKHR get_executables =
                (PFN_vkGetPipelineExecutablePropertiesKHR)vkGetDeviceProcAddr(device, "vkGetPipelineExecutablePropertiesKHR");
            PFN_vkGetPipelineExecutableStatisticsKHR get_statistics =
                (PFN_vkGetPipelineExecutableStatisticsKHR)vkGetDeviceProcAddr(device, "vkGetPipelineExecutableStatisticsKHR");
            PFN_vkGetPipelineExecutableInternalRepresentationsKHR get_representations =
                (PFN_vkGetPipelineExecutableInternalRepresentationsKHR)vkGetDeviceProcAddr(device, "vkGetPipelineExecutableInternalRepresentationsKHR");
            if (!get_executables || !get_statistics || !get_representations) {
                fprintf(stderr, "the driver lacks VK_KHR_pipeline_executable_properties\n");
                return 1;
            }
            printf("kernel %s\n", argv[f]);
            VkPipelineInfoKHR pipeline_of = {VK_STRUCTURE_TYPE_PIPELINE_INFO_KHR, NULL, pipeline};
            uint32_t executable_count = 0;
            CHECK(get_executables(device, &pipeline_of, &executable_count, NULL));
            VkPipelineExecutablePropertiesKHR *executable = calloc(executable_count, sizeof *executable);
            for (uint32_t i = 0; i < executable_count; i++)
                executable[i].sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_PROPERTIES_KHR;
            CHECK(get_executables(device, &pipeline_of, &executable_count, executable));
            for (uint32_t e = 0; e < executable_count; e++) {
                VkPipelineExecutableInfoKHR which = {VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INFO_KHR, NULL, pipeline, e};
                printf("stat Subgroup size\t%u\n", executable[e].subgroupSize);
                uint32_t statistic_count = 0;
                CHECK(get_statistics(device, &which, &statistic_count, NULL));
                VkPipelineExecutableStatisticKHR *statistic = calloc(statistic_count, sizeof *statistic);
                for (uint32_t i = 0; i < statistic_count; i++)
                    statistic[i].sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_STATISTIC_KHR;
                CHECK(get_statistics(device, &which, &statistic_count, statistic));
                for (uint32_t i = 0; i < statistic_count; i++) {
                    switch (statistic[i].format) {
                    case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_BOOL32_KHR:
                        printf("stat %s\t%u\n", statistic[i].name, statistic[i].value.b32); break;
                    case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_INT64_KHR:
                        printf("stat %s\t%lld\n", statistic[i].name, (long long)statistic[i].value.i64); break;
                    case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_UINT64_KHR:
                        printf("stat %s\t%llu\n", statistic[i].name, (unsigned long long)statistic[i].value.u64); break;
                    default:
                        printf("stat %s\t%g\n", statistic[i].name, statistic[i].value.f64); break;
                    }
                }
                uint32_t representation_count = 0;
                CHECK(get_representations(device, &which, &representation_count, NULL));
                VkPipelineExecutableInternalRepresentationKHR *representation = calloc(representation_count, sizeof *representation);
                for (uint32_t i = 0; i < representation_count; i++)
                    representation[i].sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INTERNAL_REPRESENTATION_KHR;
                CHECK(get_representations(device, &which, &representation_count, representation));
                for (uint32_t i = 0; i < representation_count; i++)
                    representation[i].pData = calloc(representation[i].dataSize + 1, 1);
                CHECK(get_representations(device, &which, &representation_count, representation));
                for (uint32_t i = 0; i < representation_count; i++) {
                    const char *text = representation[i].pData;
                    size_t length = strnlen(text, representation[i].dataSize);
                    printf("ir %s\t%zu\n", representation[i].name, length);
                    fwrite(text, 1, length, stdout);
                    printf("\n");
                }
            }
            vkDestroyPipeline(device, pipeline, NULL);
            vkDestroyShaderModule(device, module, NULL);
            free(code);
            continue;
        }

        /* run: the inputs on stdin, one output per thread. */
        size_t input_bytes;
        float *inputs = read_all(stdin, &input_bytes);
        long per_thread = strtol(argv[4], NULL, 10);
        if (per_thread < 1 || input_bytes == 0 || input_bytes % (sizeof(float) * per_thread)) {
            fprintf(stderr, "the inputs are not a whole number of threads' %ld floats\n", per_thread);
            return 1;
        }
        uint32_t threads = (uint32_t)(input_bytes / (sizeof(float) * per_thread));
        uint32_t groups = (threads + WORKGROUP - 1) / WORKGROUP;
        VkDeviceSize sizes[2] = {(VkDeviceSize)groups * WORKGROUP * per_thread * sizeof(float),
                                 (VkDeviceSize)groups * WORKGROUP * sizeof(float)};
        VkBuffer buffers[2];
        VkDeviceMemory memories[2];
        void *mapped[2];
        for (int b = 0; b < 2; b++) {
            VkBufferCreateInfo buffer_info = {VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, NULL, 0, sizes[b],
                                              VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, VK_SHARING_MODE_EXCLUSIVE, 0, NULL};
            CHECK(vkCreateBuffer(device, &buffer_info, NULL, &buffers[b]));
            VkMemoryRequirements requirements;
            vkGetBufferMemoryRequirements(device, buffers[b], &requirements);
            uint32_t type = memory_type(physical, requirements.memoryTypeBits,
                                        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
            if (type == UINT32_MAX) {
                fprintf(stderr, "no host-visible, coherent memory\n");
                return 1;
            }
            VkMemoryAllocateInfo allocate_info = {VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, NULL, requirements.size, type};
            CHECK(vkAllocateMemory(device, &allocate_info, NULL, &memories[b]));
            CHECK(vkBindBufferMemory(device, buffers[b], memories[b], 0));
            CHECK(vkMapMemory(device, memories[b], 0, VK_WHOLE_SIZE, 0, &mapped[b]));
            memset(mapped[b], 0, sizes[b]);
        }
        memcpy(mapped[0], inputs, input_bytes);

        VkDescriptorPoolSize pool_size = {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2};
        VkDescriptorPoolCreateInfo pool_info = {VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO, NULL, 0, 1, 1, &pool_size};
        VkDescriptorPool pool;
        CHECK(vkCreateDescriptorPool(device, &pool_info, NULL, &pool));
        VkDescriptorSetAllocateInfo set_info = {VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO, NULL, pool, 1, &set_layout};
        VkDescriptorSet set;
        CHECK(vkAllocateDescriptorSets(device, &set_info, &set));
        VkDescriptorBufferInfo buffer_infos[2] = {{buffers[0], 0, VK_WHOLE_SIZE}, {buffers[1], 0, VK_WHOLE_SIZE}};
        VkWriteDescriptorSet writes[2];
        for (int b = 0; b < 2; b++) {
            VkWriteDescriptorSet write = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, NULL, set, (uint32_t)b, 0, 1,
                                          VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, NULL, &buffer_infos[b], NULL};
            writes[b] = write;
        }
        vkUpdateDescriptorSets(device, 2, writes, 0, NULL);

        VkCommandPoolCreateInfo command_pool_info = {VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO, NULL, 0, 0};
        VkCommandPool command_pool;
        CHECK(vkCreateCommandPool(device, &command_pool_info, NULL, &command_pool));
        VkCommandBufferAllocateInfo command_info = {VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, NULL, command_pool,
                                                    VK_COMMAND_BUFFER_LEVEL_PRIMARY, 1};
        VkCommandBuffer commands;
        CHECK(vkAllocateCommandBuffers(device, &command_info, &commands));
        VkCommandBufferBeginInfo begin = {VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO, NULL,
                                          VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT, NULL};
        CHECK(vkBeginCommandBuffer(commands, &begin));
        vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
        vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 1, &set, 0, NULL);
        vkCmdDispatch(commands, groups, 1, 1);
        VkMemoryBarrier barrier = {VK_STRUCTURE_TYPE_MEMORY_BARRIER, NULL, VK_ACCESS_SHADER_WRITE_BIT, VK_ACCESS_HOST_READ_BIT};
        vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier,
                             0, NULL, 0, NULL);
        CHECK(vkEndCommandBuffer(commands));
        VkQueue queue;
        vkGetDeviceQueue(device, 0, 0, &queue);
        VkSubmitInfo submit = {VK_STRUCTURE_TYPE_SUBMIT_INFO, NULL, 0, NULL, NULL, 1, &commands, 0, NULL};
        CHECK(vkQueueSubmit(queue, 1, &submit, VK_NULL_HANDLE));
        CHECK(vkQueueWaitIdle(queue));
        fwrite(mapped[1], sizeof(float), threads, stdout);
    }
    return 0;
}
