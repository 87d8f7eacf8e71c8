#include "examples/generator/step_export.hpp"

#include <APIHeaderSection_MakeHeader.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_Printer.hxx>
#include <STEPCAFControl_Writer.hxx>
#include <STEPControl_Writer.hxx>
#include <StepData_StepModel.hxx>
#include <TCollection_ExtendedString.hxx>
#include <TCollection_HAsciiString.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>

#include <stdexcept>
#include <vector>

namespace loom::examples {

namespace {
Handle(TCollection_HAsciiString) str(const std::string& s) { return new TCollection_HAsciiString(s.c_str()); }

/// Silences OpenCASCADE's transfer statistics on stdout (warnings and failures still show)
/// for its lifetime, restoring the printers' levels afterwards.
class QuietTransfer {
 public:
  QuietTransfer() {
    for (const auto& p : Message::DefaultMessenger()->Printers()) {
      saved_.push_back(p->GetTraceLevel());
      p->SetTraceLevel(Message_Warning);
    }
  }
  ~QuietTransfer() {
    std::size_t i = 0;
    for (const auto& p : Message::DefaultMessenger()->Printers())
      if (i < saved_.size()) p->SetTraceLevel(saved_[i++]);
  }
  QuietTransfer(const QuietTransfer&) = delete;
  QuietTransfer& operator=(const QuietTransfer&) = delete;

 private:
  std::vector<Message_Gravity> saved_;
};
}  // namespace

void write_named_step(const TopoDS_Shape& shape, const std::string& product, const std::filesystem::path& file) {
  Handle(XCAFApp_Application) app = XCAFApp_Application::GetApplication();
  Handle(TDocStd_Document) doc;
  app->NewDocument("MDTV-XCAF", doc);
  Handle(XCAFDoc_ShapeTool) tool = XCAFDoc_DocumentTool::ShapeTool(doc->Main());
  const TDF_Label label = tool->AddShape(shape, false);
  TDataStd_Name::Set(label, TCollection_ExtendedString(product.c_str()));

  const QuietTransfer quiet;
  Interface_Static::SetCVal("write.step.schema", "AP214IS");
  Interface_Static::SetCVal("write.step.unit", "MM");
  STEPCAFControl_Writer writer;
  writer.SetNameMode(true);
  writer.SetColorMode(false);
  writer.SetLayerMode(false);
  if (!writer.Transfer(doc, STEPControl_AsIs)) {
    app->Close(doc);
    throw std::runtime_error("STEP transfer failed for " + file.string());
  }
  // Fixed header: no wall-clock time, no directory, so the bytes depend on the shape only.
  Handle(StepData_StepModel) model = writer.ChangeWriter().Model();
  APIHeaderSection_MakeHeader header(model);
  header.SetName(str(file.filename().string()));
  header.SetTimeStamp(str(kStepTimeStamp));
  header.SetAuthorValue(1, str("loom example generator"));
  header.SetOrganizationValue(1, str("loom"));
  header.SetOriginatingSystem(str("loom_example_gen (OpenCASCADE)"));
  header.SetAuthorisation(str(""));
  header.Apply(model);
  // Written beside the target and renamed: never a half-written file under its name.
  std::filesystem::path tmp = file;
  tmp += ".part";
  const IFSelect_ReturnStatus st = writer.Write(tmp.string().c_str());
  app->Close(doc);
  if (st != IFSelect_RetDone) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error("cannot write STEP file " + file.string());
  }
  std::filesystem::rename(tmp, file);
}

}  // namespace loom::examples
